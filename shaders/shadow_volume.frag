#version 330
// One flat color: invisible during the stencil count (color writes off), translucent when the
// volumes are shown, a heat-map color per stencil count in the overlay.
uniform vec4 u_color;
out vec4 f_color;

void main() {
    f_color = u_color;
}
