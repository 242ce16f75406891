#version 330
in vec3 v_radiance;
out vec4 f_color;

void main() {
    f_color = vec4(v_radiance, 1.0);
}
