// Surface detail: texture-mapped Od and bump-mapped normals (include after "lighting").
// Used only by the *_tex programs, so materials without texture or bump keep the exact
// output of flat / gouraud / phong.
//
// Texture: Od(u, v) = u_Od * image(s u, s v) (image: linear RGB), or a checker of u_Od and
// u_texture_color2 with s x s cells over [0, 1] uv; s = texture_scale.
// Bump (Blinn 1978): a height field H(x, y) in [0, 1] over pattern coordinates x = s u,
// y = s v, raised bump_scale pattern cells high: N' = normalize(N - k (H_x T + H_y B)),
// with T, B the unit surface directions of increasing u and v (orthogonalized against N).

#define TEXTURE_NONE 0
#define TEXTURE_CHECKER 1
#define TEXTURE_IMAGE 2
#define BUMP_NONE 0
#define BUMP_BUMPS 1
#define BUMP_IMAGE 2

uniform int u_texture_mode;
uniform float u_texture_scale;
uniform vec3 u_texture_color2;
uniform sampler2D u_texture;      // texture unit 0
uniform int u_bump_mode;
uniform float u_bump_scale;
uniform sampler2D u_bump_map;     // texture unit 1, height in the red channel

vec3 surface_od(vec2 uv) {
    vec2 p = uv * u_texture_scale;
    if (u_texture_mode == TEXTURE_CHECKER) {
        vec2 cell = floor(p);
        return mod(cell.x + cell.y, 2.0) < 0.5 ? u_Od : u_texture_color2;
    }
    if (u_texture_mode == TEXTURE_IMAGE) return u_Od * textureLod(u_texture, p, 0.0).rgb;
    return u_Od;
}

// (dH/dx, dH/dy) in pattern coordinates.
vec2 height_gradient(vec2 uv) {
    vec2 p = uv * u_texture_scale;
    if (u_bump_mode == BUMP_BUMPS) {  // H = 0.5 + 0.5 sin(2 pi x) sin(2 pi y)
        const float TAU = 6.28318530718;
        return 0.5 * TAU * vec2(cos(TAU * p.x) * sin(TAU * p.y), sin(TAU * p.x) * cos(TAU * p.y));
    }
    if (u_bump_mode == BUMP_IMAGE) {
        vec2 texel = 1.0 / vec2(textureSize(u_bump_map, 0));
        float hx = textureLod(u_bump_map, p + vec2(texel.x, 0.0), 0.0).r
                 - textureLod(u_bump_map, p - vec2(texel.x, 0.0), 0.0).r;
        float hy = textureLod(u_bump_map, p + vec2(0.0, texel.y), 0.0).r
                 - textureLod(u_bump_map, p - vec2(0.0, texel.y), 0.0).r;
        return vec2(hx / (2.0 * texel.x), hy / (2.0 * texel.y));
    }
    return vec2(0.0);
}

vec3 bump_normal(vec3 n, vec3 dpdu, vec3 dpdv, vec2 uv) {
    if (u_bump_mode == BUMP_NONE) return n;
    vec3 t = dpdu - n * dot(n, dpdu);
    t = length(t) > 1e-20 ? normalize(t) : vec3(0.0);
    vec3 b = dpdv - n * dot(n, dpdv) - t * dot(t, dpdv);
    b = length(b) > 1e-20 ? normalize(b) : vec3(0.0);
    vec2 g = height_gradient(uv);
    return normalize(n - u_bump_scale * (g.x * t + g.y * b));
}

// A triangle's dP/du and dP/dv from its corners and their uvs (zero where uv is degenerate).
void triangle_tangents(vec3 p0, vec3 p1, vec3 p2, vec2 t0, vec2 t1, vec2 t2,
                       out vec3 dpdu, out vec3 dpdv) {
    vec3 e1 = p1 - p0, e2 = p2 - p0;
    vec2 d1 = t1 - t0, d2 = t2 - t0;
    float det = d1.x * d2.y - d1.y * d2.x;
    if (abs(det) < 1e-20) { dpdu = vec3(0.0); dpdv = vec3(0.0); return; }
    dpdu = (e1 * d2.y - e2 * d1.y) / det;
    dpdv = (e2 * d1.x - e1 * d2.x) / det;
}
