// Display encodings: the GLSL mirror of app/shadelab/shading/conventions.py (to_srgb8,
// heat_map). The constants (SRGB_*, HEAT_STOP_0..4, HEAT_EPS) are #defines generated ahead of
// this text by the program loader from that module, so both encode alike.

vec3 to_srgb(vec3 linear) {
    vec3 c = clamp(linear, 0.0, 1.0);
    vec3 lo = SRGB_SLOPE * c;
    vec3 hi = SRGB_SCALE * pow(c, vec3(1.0 / SRGB_GAMMA)) - SRGB_OFFSET;
    return mix(hi, lo, vec3(lessThanEqual(c, vec3(SRGB_LINEAR_MAX))));
}

// to_srgb for the display pass: the power segment as conventions.py's SRGB_POLY, a polynomial
// in t = c^(1/4) (no pow: llvmpipe's costs a log2 and an exp2 approximation per channel);
// conventions.display_srgb8 mirrors it, within 7e-5 of an 8-bit code of to_srgb.
vec3 to_srgb_display(vec3 linear) {
    vec3 c = clamp(linear, 0.0, 1.0);
    vec3 t = sqrt(sqrt(c));
    vec3 p = vec3(SRGB_POLY_8);
    p = p * t + SRGB_POLY_7;
    p = p * t + SRGB_POLY_6;
    p = p * t + SRGB_POLY_5;
    p = p * t + SRGB_POLY_4;
    p = p * t + SRGB_POLY_3;
    p = p * t + SRGB_POLY_2;
    p = p * t + SRGB_POLY_1;
    p = p * t + SRGB_POLY_0;
    return mix(p, SRGB_SLOPE * c, vec3(lessThanEqual(c, vec3(SRGB_LINEAR_MAX))));
}

// Black -> blue -> green -> yellow -> red as t goes 0 -> 1.
vec3 heat(float t) {
    float s = clamp(t, 0.0, 1.0) * 4.0;
    if (s < 1.0) return mix(HEAT_STOP_0, HEAT_STOP_1, s);
    if (s < 2.0) return mix(HEAT_STOP_1, HEAT_STOP_2, s - 1.0);
    if (s < 3.0) return mix(HEAT_STOP_2, HEAT_STOP_3, s - 2.0);
    return mix(HEAT_STOP_3, HEAT_STOP_4, s - 3.0);
}
