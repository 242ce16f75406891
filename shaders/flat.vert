#version 330
invariant gl_Position;  // same depth in every pass (ambient, per-light, volumes)
// Flat shading: the equation once per triangle, at its centroid, with the true face normal.
#include "lighting"

uniform mat4 u_clip_from_world;
uniform vec3 u_eye;

in vec3 in_position;
in vec3 in_face_normal;
in vec3 in_centroid;

flat out vec3 v_color;

void main() {
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
    vec3 n = in_face_normal;
    if (dot(n, u_eye - in_centroid) < 0.0) n = -n;   // seen from behind: light the back
    v_color = shade(in_centroid, n, u_eye, u_Od);
}
