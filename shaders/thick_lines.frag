#version 330
// Overlay lines drawn as quads (thick_lines.vert); the same color rule as lines.frag.
uniform float u_scale;          // 1 / exposure, so overlays show their own color on screen

in vec3 v_color;
out vec4 f_color;

void main() {
    f_color = vec4(v_color * u_scale, 1.0);
}
