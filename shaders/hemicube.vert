#version 330
// Hemicube item buffer: every patch drawn with its id + 1 (0 is the cleared background).
uniform mat4 u_clip_from_world;

in vec3 in_position;
in uint in_id;

flat out uint v_id;

void main() {
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
    v_id = in_id;
}
