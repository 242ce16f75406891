#version 330
// Evaluates the shared lighting include per fragment, exactly as the Phong program does.
#include "lighting"

uniform vec3 u_eye;

flat in vec3 v_position;
flat in vec3 v_normal;
flat in vec3 v_od;

out vec4 f_color;

void main() {
    f_color = vec4(shade(v_position, v_normal, u_eye, v_od), 1.0);
}
