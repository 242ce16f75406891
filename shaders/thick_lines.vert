#version 330
// Overlay segments as screen-space quads of a given pixel width (core profiles cap
// glLineWidth at 1): each segment is two triangles whose corners carry both ends; the
// vertex shader pushes a corner sideways by half the width, perpendicular to the segment
// as it appears on screen.
uniform mat4 u_clip_from_world;
uniform float u_depth_bias;     // pulls lines toward the eye (clip-space z), against z-fighting
uniform vec2 u_viewport;        // target size, pixels
uniform float u_width;          // line width, pixels

in vec3 in_position;            // this corner's end of the segment
in vec3 in_other;               // the segment's other end
in vec3 in_color;
in float in_side;               // +1 / -1: which side of the segment this corner is on

out vec3 v_color;

void main() {
    vec4 a = u_clip_from_world * vec4(in_position, 1.0);
    vec4 b = u_clip_from_world * vec4(in_other, 1.0);
    vec2 sa = a.xy / max(abs(a.w), 1e-9) * u_viewport * 0.5;
    vec2 sb = b.xy / max(abs(b.w), 1e-9) * u_viewport * 0.5;
    vec2 d = sb - sa;
    float len = length(d);
    vec2 dir = len > 1e-6 ? d / len : vec2(1.0, 0.0);
    vec2 normal = vec2(-dir.y, dir.x);
    vec2 offset = normal * in_side * u_width / u_viewport;  // (width / 2) / (viewport / 2)
    gl_Position = a;
    gl_Position.xy += offset * abs(a.w);
    gl_Position.z -= u_depth_bias * gl_Position.w;
    v_color = in_color;
}
