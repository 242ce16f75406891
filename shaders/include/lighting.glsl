// The lecture's lighting equation: the GLSL mirror of app/shading/reference.py.
// Same function names, same argument order; tests/test_glsl_parity.py holds them together.
// Conventions: to_light (L) and to_eye (V) point away from the surface; normals are unit;
// colors are linear RGB.
//
//   I = Le + Ia ka Od + sum_i S_i f_att,i Ip,i [kd Od (N.L_i) + ks Os (R_i.V)^n]
//   with any of ambient, diffuse, specular (0), f_att and S_i (1) switched off (u_terms_off)
//   f_att = 1 | 1/d^2 | min(1/(c1 + c2 d + c3 d^2), 1);   R = 2N(N.L) - L;   H = (L+V)/|L+V|

// Generated ahead of this text by the program loader (shadelab/gl/programs.py) from the Python
// table (shadelab/shading/codes.py, shadelab/constants.py): MAX_LIGHTS, SHADING_EPS, the light
// kinds LIGHT_POINT | LIGHT_DIRECTIONAL | LIGHT_SPOT, the attenuation modes ATTENUATION_NONE |
// ATTENUATION_INVERSE_SQUARE | ATTENUATION_LECTURE, SPECULAR_PHONG | SPECULAR_BLINN and the
// term bits TERM_AMBIENT | TERM_DIFFUSE | TERM_SPECULAR | TERM_ATTENUATION | TERM_SHADOW.
//
// The renderer compiles one variant per light configuration: NUM_LIGHTS, LIGHT_KINDS and
// LIGHT_ATTENUATIONS (2 bits per light, light i at bits 2i..2i+1, as uint literals) and
// SPECULAR_MODEL. The loop then unrolls and every branch on a light's kind or attenuation folds
// away at compile time; llvmpipe runs masked branches and uniform-bounded loops several times
// slower. Without the defines the uniforms decide (the parity harness tests both ways).
#ifdef NUM_LIGHTS
#define LIGHT_COUNT NUM_LIGHTS
#define LIGHT_KIND(i) int((LIGHT_KINDS >> (2u * uint(i))) & 3u)
#define LIGHT_ATTENUATION(i) int((LIGHT_ATTENUATIONS >> (2u * uint(i))) & 3u)
#else
#define LIGHT_COUNT u_num_lights
#define LIGHT_KIND(i) u_light_kind[i]
#define LIGHT_ATTENUATION(i) u_light_attenuation[i]
#endif
#ifndef SPECULAR_MODEL
#define SPECULAR_MODEL u_specular_model
#endif
// PREMULTIPLIED (programs whose Od is the material's u_Od, i.e. without surface detail): the
// renderer folds the factors that are the same at every point on the CPU, once per material and
// light, into u_ambient = u_ambient_on (Le + Ia ka Od), u_light_diffuse[i] = S_i Ip,i kd Od and
// u_light_specular[i] = S_i Ip,i ks Os; a fragment then reads 3 + 3 per light uniforms instead
// of 10 + 3 per light (llvmpipe pays for every uniform a fragment reads). Same equation, same
// order of the per-point factors. Without the define the uniforms below decide: the parity
// harness, and every replacement of this chunk (a student's), which the renderer compiles
// without PREMULTIPLIED.
#ifdef PREMULTIPLIED
#define LIGHT_S(i) 1.0
#define LIGHT_IP(i) vec3(1.0)
#else
#define LIGHT_S(i) u_light_S[i]
#define LIGHT_IP(i) u_light_Ip[i]
#endif

uniform int u_num_lights;                        // lights in use, <= MAX_LIGHTS
uniform int u_light_kind[MAX_LIGHTS];            // LIGHT_POINT | LIGHT_DIRECTIONAL | LIGHT_SPOT
uniform vec3 u_light_position[MAX_LIGHTS];       // world space (point, spot)
uniform vec3 u_light_direction[MAX_LIGHTS];      // unit, the way the light travels
uniform vec3 u_light_Ip[MAX_LIGHTS];             // RGB intensity
uniform int u_light_attenuation[MAX_LIGHTS];     // ATTENUATION_NONE | _INVERSE_SQUARE | _LECTURE
uniform vec3 u_light_c[MAX_LIGHTS];              // c1, c2, c3 of the lecture's f_att
uniform vec2 u_light_spot[MAX_LIGHTS];           // cos(cone half-angle), falloff exponent
uniform float u_light_S[MAX_LIGHTS];             // shadow factor S_i: 1 lit, 0 blocked
uniform float u_terminator;                      // shadow-volume lit pass: 1 fades S_i by the
                                                 // point's threshold t; 0: off (exact equation)

uniform int u_terms_off;                         // TERM_* bits of the terms switched off
                                                 // (0, the default: the whole equation)
#define TERM_OFF(t) ((u_terms_off & (t)) != 0)

uniform vec3 u_Ia;                               // ambient intensity
uniform float u_ambient_on;                      // 1: add Le + Ia ka Od (first pass only)
uniform int u_specular_model;                    // SPECULAR_PHONG (R.V)^n | SPECULAR_BLINN (N.H)^n

uniform float u_ka;
uniform float u_kd;
uniform float u_ks;
uniform float u_n;
uniform vec3 u_Od;
uniform vec3 u_Os;
uniform vec3 u_emission;

uniform vec3 u_ambient;                          // PREMULTIPLIED: u_ambient_on (Le + Ia ka Od)
uniform vec3 u_light_diffuse[MAX_LIGHTS];        // PREMULTIPLIED: S_i Ip,i kd Od
uniform vec3 u_light_specular[MAX_LIGHTS];       // PREMULTIPLIED: S_i Ip,i ks Os

float lambert(vec3 n, vec3 to_light) {
    return max(dot(n, to_light), 0.0);
}

vec3 reflect_light(vec3 n, vec3 to_light) {
    return 2.0 * n * dot(n, to_light) - to_light;
}

// cos^n for cos > 0, else 0 (n = 0 gives 1 inside the lobe).
float lobe_power(float cosine, float shininess) {
    return cosine > 0.0 ? pow(max(cosine, SHADING_EPS), shininess) : 0.0;
}

float phong_specular(vec3 n, vec3 to_light, vec3 to_eye, float shininess) {
    float lobe = lobe_power(dot(reflect_light(n, to_light), to_eye), shininess);
    return dot(n, to_light) > 0.0 ? lobe : 0.0;
}

vec3 halfway(vec3 to_light, vec3 to_eye) {
    vec3 h = to_light + to_eye;
    float len = length(h);
    return len > SHADING_EPS ? h / len : vec3(0.0);
}

float blinn_phong_specular(vec3 n, vec3 to_light, vec3 to_eye, float shininess) {
    float lobe = lobe_power(dot(n, halfway(to_light, to_eye)), shininess);
    return dot(n, to_light) > 0.0 ? lobe : 0.0;
}

#ifdef TERMINATOR
// The threshold t at the point being shaded, set by the program's main before shade():
// u_terminator * sum_k b_k t_k / |sum_k b_k N_k| (Phong), u_terminator * t_k (Gouraud), with
// t_k the corner's vertex attribute in_terminator (geometry/normals.py vertex_terminators,
// threshold_at). 0: no fade.
float terminator_t = 0.0;
#endif

// The self-shadow part of S_i on a smooth mesh: smoothstep(t, 2t, N.L); 1 for t = 0.
// The faces turned from the light sit in their own shadow volume while their shading normals
// reach N.L <= t; fading to 0 there joins the two with no step (terminator_softening in
// shading/reference.py).
float terminator_softening(float n_dot_l, float threshold) {
    if (threshold <= 0.0) return 1.0;
    float x = clamp((n_dot_l - threshold) / threshold, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

float attenuation(float distance, int mode, vec3 c) {
    float inverse_square = 1.0 / max(distance * distance, SHADING_EPS);
    float lecture = min(1.0 / max(c.x + c.y * distance + c.z * distance * distance,
                                  SHADING_EPS), 1.0);
    return mode == ATTENUATION_INVERSE_SQUARE ? inverse_square
         : (mode == ATTENUATION_LECTURE ? lecture : 1.0);
}

float spot_factor(vec3 to_light, vec3 axis, float cos_cone, float exponent) {
    float cos_phi = dot(-to_light, axis);
    return cos_phi >= cos_cone ? pow(max(cos_phi, 0.0), exponent) : 0.0;
}

// One light's diffuse + specular contribution at a point (S_i included).
vec3 shade_light(int i, vec3 position, vec3 n, vec3 to_eye, vec3 od) {
    // Branch-free where it is cheap: llvmpipe runs divergent branches under masks.
    int kind = LIGHT_KIND(i);
    vec3 delta = u_light_position[i] - position;
    float distance = length(delta);
    vec3 to_point = distance > SHADING_EPS ? delta / distance : vec3(0.0);
    bool directional = kind == LIGHT_DIRECTIONAL;
    vec3 to_light = directional ? -u_light_direction[i] : to_point;
    float f_att = directional || TERM_OFF(TERM_ATTENUATION) ? 1.0
                : attenuation(distance, LIGHT_ATTENUATION(i), u_light_c[i]);
    float spot = 1.0;
    if (kind == LIGHT_SPOT)
        spot = spot_factor(to_light, u_light_direction[i], u_light_spot[i].x, u_light_spot[i].y);
    float specular;
#ifdef NO_SPECULAR  // the renderer's twin for ks = 0 (or the term off): ks Os times the lobe is 0
    specular = 0.0;
#else
    if (SPECULAR_MODEL == SPECULAR_BLINN) specular = blinn_phong_specular(n, to_light, to_eye, u_n);
    else specular = phong_specular(n, to_light, to_eye, u_n);
#endif
#ifdef TERMINATOR  // the shadow-volume lit pass; elsewhere no term
    float s = LIGHT_S(i) * terminator_softening(dot(n, to_light), terminator_t);
#else
    float s = LIGHT_S(i);
#endif
    if (TERM_OFF(TERM_SHADOW)) s = 1.0;          // the terms switched off (u_terms_off)
    if (TERM_OFF(TERM_SPECULAR)) specular = 0.0;
    vec3 scale = s * f_att * spot * LIGHT_IP(i);
#ifdef PREMULTIPLIED
    float diffuse = TERM_OFF(TERM_DIFFUSE) ? 0.0 : lambert(n, to_light);
    return scale * (u_light_diffuse[i] * diffuse + u_light_specular[i] * specular);
#else
    if (TERM_OFF(TERM_DIFFUSE)) od = vec3(0.0);
    return scale * (u_kd * od * lambert(n, to_light) + u_ks * u_Os * specular);
#endif
}

vec3 shade(vec3 position, vec3 n, vec3 eye, vec3 od) {
    vec3 to_eye = eye - position;
    float len = length(to_eye);
    to_eye = len > SHADING_EPS ? to_eye / len : vec3(0.0);
#ifdef PREMULTIPLIED  // (TERM_AMBIENT folded into u_ambient by the renderer)
    vec3 color = u_ambient;
#else
    vec3 color = u_ambient_on * (u_emission + u_Ia * u_ka * od);
    if (TERM_OFF(TERM_AMBIENT)) color = u_ambient_on * u_emission;
#endif
    for (int i = 0; i < LIGHT_COUNT; ++i)
        color += shade_light(i, position, n, to_eye, od);
    return color;
}
