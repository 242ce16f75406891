#version 330
// Radiosity display: per-vertex radiance solved offline, interpolated by the rasterizer
// (the lecture's "radiosity & Gouraud shading" pipeline; view-independent).
uniform mat4 u_clip_from_world;

in vec3 in_position;
in vec3 in_radiance;

out vec3 v_radiance;

void main() {
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
    v_radiance = in_radiance;
}
