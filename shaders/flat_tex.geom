#version 330
invariant gl_Position;  // same depth in every pass (ambient, per-light, volumes)
// Flat + texture/bump: the equation once per face at its centroid, with the face normal
// bumped at the centroid's uv. The result is split as I = A Od + B (the equation is linear
// in Od), so the fragment modulates A by the texture per pixel: texture detail stays sharp
// while the lighting stays one value per face.
#include "lighting"
#include "surface"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

uniform mat4 u_clip_from_world;
uniform vec3 u_eye;

in vec3 g_position[];
in vec3 g_face_normal[];
in vec3 g_centroid[];
in vec2 g_uv[];

flat out vec3 v_a;
flat out vec3 v_b;
out vec2 v_uv;

void main() {
    vec3 c = g_centroid[0];
    vec2 uv_c = (g_uv[0] + g_uv[1] + g_uv[2]) / 3.0;
    vec3 n = g_face_normal[0];
    if (dot(n, u_eye - c) < 0.0) n = -n;   // seen from behind: light the back
    vec3 dpdu, dpdv;
    triangle_tangents(g_position[0], g_position[1], g_position[2], g_uv[0], g_uv[1], g_uv[2],
                      dpdu, dpdv);
    n = bump_normal(n, dpdu, dpdv, uv_c);
    vec3 b = shade(c, n, u_eye, vec3(0.0));
    vec3 a = shade(c, n, u_eye, vec3(1.0)) - b;
    for (int k = 0; k < 3; ++k) {
        gl_Position = u_clip_from_world * vec4(g_position[k], 1.0);
        v_a = a;
        v_b = b;
        v_uv = g_uv[k];
        EmitVertex();
    }
    EndPrimitive();
}
