#version 330
// Parity harness: one point per sample, placed on its own pixel of an N x 1 float target.
uniform int u_count;

in vec3 in_position;
in vec3 in_normal;
in vec3 in_od;

flat out vec3 v_position;
flat out vec3 v_normal;
flat out vec3 v_od;

void main() {
    float x = (float(gl_VertexID) + 0.5) / float(u_count) * 2.0 - 1.0;
    gl_Position = vec4(x, 0.0, 0.0, 1.0);
    gl_PointSize = 1.0;
    v_position = in_position;
    v_normal = in_normal;
    v_od = in_od;
}
