#version 330
// Gouraud shading with surface detail: pass-through; the geometry shader lights the corners.
in vec3 in_position;
in vec3 in_normal;
in vec3 in_face_normal;
in vec3 in_centroid;
in vec2 in_uv;
in float in_terminator;

out vec3 g_position;
out vec3 g_normal;
out vec3 g_face_normal;
out vec3 g_centroid;
out vec2 g_uv;
out float g_terminator;

void main() {
    g_position = in_position;
    g_normal = in_normal;
    g_face_normal = in_face_normal;
    g_centroid = in_centroid;
    g_uv = in_uv;
    g_terminator = in_terminator;
}
