#version 330
invariant gl_Position;  // same depth in every pass (ambient, per-light, volumes)
// Phong + texture/bump: each triangle's dP/du and dP/dv go to the fragments (constant per
// triangle), which bump the interpolated normal and texture Od per pixel.
#include "lighting"
#include "surface"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

uniform mat4 u_clip_from_world;

in vec3 g_position[];
in vec3 g_normal[];
in float g_terminator[];
in vec2 g_uv[];

out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
#ifdef TERMINATOR
out float v_sine;  // the corner's terminator threshold t_k
#endif
flat out vec3 v_dpdu;
flat out vec3 v_dpdv;

void main() {
    vec3 dpdu, dpdv;
    triangle_tangents(g_position[0], g_position[1], g_position[2], g_uv[0], g_uv[1], g_uv[2],
                      dpdu, dpdv);
    for (int k = 0; k < 3; ++k) {
        gl_Position = u_clip_from_world * vec4(g_position[k], 1.0);
        v_position = g_position[k];
        v_normal = g_normal[k];
        v_uv = g_uv[k];
#ifdef TERMINATOR
        v_sine = g_terminator[k];
#endif
        v_dpdu = dpdu;
        v_dpdv = dpdv;
        EmitVertex();
    }
    EndPrimitive();
}
