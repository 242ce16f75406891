#version 330
#include "lighting"
#include "surface"

uniform vec3 u_eye;

in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
#ifdef TERMINATOR
in float v_sine;
#endif
flat in vec3 v_dpdu;
flat in vec3 v_dpdv;

out vec4 f_color;

void main() {
    vec3 n = normalize(v_normal);
#ifdef TERMINATOR
    terminator_t = u_terminator * v_sine / max(length(v_normal), 1e-12);
#endif
    if (!gl_FrontFacing) n = -n;   // seen from behind: light the back
    n = bump_normal(n, v_dpdu, v_dpdv, v_uv);
    f_color = vec4(shade(v_position, n, u_eye, surface_od(v_uv)), 1.0);
}
