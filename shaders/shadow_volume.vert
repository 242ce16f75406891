#version 330
invariant gl_Position;  // same depth in every pass (ambient, per-light, volumes)
// Shadow-volume geometry: homogeneous world positions, extruded vertices have w = 0
// (points at infinity, drawn with an infinite far plane or depth clamp). Also draws the
// silhouette lines and, with u_clip_from_world = identity, full-screen overlays.
uniform mat4 u_clip_from_world;

in vec4 in_position;

void main() {
    gl_Position = u_clip_from_world * in_position;
}
