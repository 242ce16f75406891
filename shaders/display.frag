#version 330
// Display pass: linear radiance -> exposure -> sRGB, or a heat map of |a - b| (compare mode).
uniform sampler2D t_image;      // linear RGB radiance (RGBA32F)
uniform sampler2D t_other;      // second image for the difference heat map
uniform int u_mode;             // 0: tone map t_image, 1: heat map of |t_image - t_other|
uniform float u_exposure;       // scale applied before display
uniform float u_diff_scale;     // heat map: this difference (after exposure) is full red
uniform int u_tonemap;          // 0: clamp to [0, 1], 1: Reinhard x / (1 + x)
uniform int u_clipping;         // 1: stripe the pixels clamping cuts (a channel above 1)

// The viewer compiles one variant per (mode, tone map, clipping), DISPLAY_MODE, DISPLAY_TONEMAP
// and DISPLAY_CLIPPING defined: llvmpipe runs every branch of a fragment under masks (the heat
// map, Reinhard and the stripes cost each pixel as much again as the tone map it uses).
// Without the defines the uniforms decide.
#ifdef DISPLAY_MODE
#define MODE DISPLAY_MODE
#define TONEMAP DISPLAY_TONEMAP
#define CLIPPING DISPLAY_CLIPPING
#else
#define MODE u_mode
#define TONEMAP u_tonemap
#define CLIPPING u_clipping
#endif

#include "color"   // to_srgb_display and heat: conventions.py's encodings, mirrored

in vec2 v_uv;
out vec4 f_color;

void main() {
    vec3 a = texture(t_image, v_uv).rgb * u_exposure;
    if (MODE == 1) {
        vec3 b = texture(t_other, v_uv).rgb * u_exposure;
        vec3 d = abs(a - b);
        f_color = vec4(heat(max(d.r, max(d.g, d.b)) / max(u_diff_scale, HEAT_EPS)), 1.0);
    } else {
        vec3 mapped = TONEMAP == 1 ? a / (1.0 + a) : a;
        vec3 rgb = to_srgb_display(mapped);
        if (CLIPPING == 1 && TONEMAP == 0 && max(a.r, max(a.g, a.b)) > 1.0) {
            // magenta / black diagonal stripes, 8 pixels apart: readable from the back row
            float stripe = mod(floor((gl_FragCoord.x + gl_FragCoord.y) / 4.0), 2.0);
            rgb = stripe < 1.0 ? vec3(1.0, 0.0, 1.0) : vec3(0.0);
        }
        f_color = vec4(rgb, 1.0);
    }
}
