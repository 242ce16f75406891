#version 330
// Phong shading with surface detail: pass-through; the geometry shader adds the tangents.
in vec3 in_position;
in vec3 in_normal;
in float in_terminator;
in vec2 in_uv;

out vec3 g_position;
out vec3 g_normal;
out float g_terminator;
out vec2 g_uv;

void main() {
    g_position = in_position;
    g_normal = in_normal;
    g_terminator = in_terminator;
    g_uv = in_uv;
}
