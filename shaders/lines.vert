#version 330
// Overlay lines (wireframe, normal glyphs, probe arrows) and vertex-colored triangles.
uniform mat4 u_clip_from_world;
uniform float u_depth_bias;     // pulls lines toward the eye (clip-space z), against z-fighting

in vec3 in_position;
in vec3 in_color;

out vec3 v_color;

void main() {
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
    gl_Position.z -= u_depth_bias * gl_Position.w;
    v_color = in_color;
}
