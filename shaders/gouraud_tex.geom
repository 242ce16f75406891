#version 330
invariant gl_Position;  // same depth in every pass (ambient, per-light, volumes)
// Gouraud + texture/bump: the equation at each corner, with the corner normal bumped at the
// corner's uv (the triangle's dP/du, dP/dv), split as I = A Od + B; A and B are interpolated
// and the fragment applies the texture per pixel. Bumps smaller than a triangle cannot show
// in Gouraud shading: that is the lecture's point about per-vertex lighting.
#include "lighting"
#include "surface"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

uniform mat4 u_clip_from_world;
uniform vec3 u_eye;

in vec3 g_position[];
in vec3 g_normal[];
in vec3 g_face_normal[];
in vec3 g_centroid[];
in vec2 g_uv[];
in float g_terminator[];

out vec3 v_a;
out vec3 v_b;
out vec2 v_uv;

void main() {
    vec3 dpdu, dpdv;
    triangle_tangents(g_position[0], g_position[1], g_position[2], g_uv[0], g_uv[1], g_uv[2],
                      dpdu, dpdv);
    for (int k = 0; k < 3; ++k) {
        vec3 p = g_position[k];
        vec3 n = normalize(g_normal[k]);
#ifdef TERMINATOR
        terminator_t = u_terminator * g_terminator[k];
#endif
        if (dot(g_face_normal[k], u_eye - p) < 0.0) n = -n;  // back face: flip
        n = bump_normal(n, dpdu, dpdv, g_uv[k]);
        vec3 b = shade(p, n, u_eye, vec3(0.0));
        gl_Position = u_clip_from_world * vec4(p, 1.0);
        v_a = shade(p, n, u_eye, vec3(1.0)) - b;
        v_b = b;
        v_uv = g_uv[k];
        EmitVertex();
    }
    EndPrimitive();
}
