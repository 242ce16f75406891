#version 330
#include "lighting"
#include "surface"

in vec3 v_a;
in vec3 v_b;
in vec2 v_uv;
out vec4 f_color;

void main() {
    f_color = vec4(v_a * surface_od(v_uv) + v_b, 1.0);
}
