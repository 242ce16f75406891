#version 330
invariant gl_Position;  // same depth in every pass (ambient, per-light, volumes)
// Gouraud shading: the equation per vertex; the rasterizer interpolates the colors.
#include "lighting"

uniform mat4 u_clip_from_world;
uniform vec3 u_eye;

in vec3 in_position;
in vec3 in_normal;
in vec3 in_face_normal;
in float in_terminator;

out vec3 v_color;

void main() {
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
    vec3 n = normalize(in_normal);
#ifdef TERMINATOR
    terminator_t = u_terminator * in_terminator;
#endif
    if (dot(in_face_normal, u_eye - in_position) < 0.0) n = -n;  // back face: flip
    v_color = shade(in_position, n, u_eye, u_Od);
}
