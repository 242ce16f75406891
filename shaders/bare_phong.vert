#version 330
// Benchmark baseline: the plainest per-fragment Phong draw moderngl can do (one VAO, one light).
uniform mat4 u_clip_from_world;
in vec3 in_position;
in vec3 in_normal;
out vec3 v_position;
out vec3 v_normal;

void main() {
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
    v_position = in_position;
    v_normal = in_normal;
}
