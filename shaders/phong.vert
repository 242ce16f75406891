#version 330
invariant gl_Position;  // same depth in every pass (ambient, per-light, volumes)
// Phong shading: normals interpolated here, renormalized and shaded per fragment.
uniform mat4 u_clip_from_world;

in vec3 in_position;
in vec3 in_normal;
in float in_terminator;
in vec2 in_uv;

out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
#ifdef TERMINATOR
out float v_sine;  // the corner's terminator threshold t_k
#endif

void main() {
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
    v_position = in_position;
    v_normal = in_normal;
    v_uv = in_uv;
#ifdef TERMINATOR
    v_sine = in_terminator;
#endif
}
