// Shared by the upsampling's dispatches (multires/upsample.comp) and its push into
// level 0 (multires/upsample_level0.frag), docs/algorithm.md section 3, step 7.
// Include after frame.glsl and after declaring `taps` (rgba32f image2DArray)
// and the specialisation constant INTERPOLATE.
#ifndef UPSAMPLE_GLSL
#define UPSAMPLE_GLSL

// Texel alpha in the illumination buffer: 1 = a patch the gather shaded;
// 0.5 = pulled (the mean of its children, for texels split into finer
// patches); 0 = no value (yet). 0.75 = pushed (from the coarser level), a
// value that goes only to the taps and to `indirect`, never to the buffer.
const float PULLED = 0.5;
const float PUSHED = 0.75;

ivec2 level_size(int l) { return ivec2(run.output_size) >> l; }

bool inside(ivec2 q, int l) { return all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, level_size(l))); }

// Taps: the dispatch that gives a level l >= 1 its final values writes one
// texel per texel of l into `taps` (layer l % 2): rgb its value, alpha these
// bits (small integers, exact in a float). The texel holds a value; it is on
// the same surface as its neighbour E (x + 1, y), S (x, y + 1), SE (x + 1,
// y + 1), SW (x - 1, y + 1); it is fully covered (coverage 1). A 2x2
// footprint's four taps then hold every pair's relation, so the push into
// l - 1 reads one texel per tap and tests nothing: on CPU drivers the fetches
// and tests were its cost.
const uint TAP_VALUE = 1u;
const uint TAP_E = 2u;
const uint TAP_S = 4u;
const uint TAP_SE = 8u;
const uint TAP_SW = 16u;
const uint TAP_FULL = 32u;

// The pushed value of texel p of `level`, from the taps of level + 1. A texel
// without a value whose parent splits is a patch or has no geometry, so the
// texels pushed here have a parent that does not split: it lies inside the
// coarser level and is smooth, one surface at the refinement's thresholds.
// The parent's geometry therefore stands for the texel's in the same-surface
// test, which the taps have done once per pair of coarser texels.
// Returns the value in rgb and the parent's tap bits in alpha.
vec4 push_value(ivec2 p, int level) {
    int up = level + 1;
    ivec2 parent = p >> 1;
    ivec2 size = level_size(up);
    if (!INTERPOLATE) return imageLoad(taps, ivec3(min(parent, size - 1), up & 1));
    // Texel centre in the coarser level's texel coordinates.
    vec2 c = (vec2(p) + 0.5) * 0.5 - 0.5;
    ivec2 base = ivec2(floor(c));
    // At the image border the 2x2 footprint would leave the level: keep it
    // inside, which turns the weights into a linear extrapolation (fractions
    // outside 0..1). Without this, border pixels would repeat the value of a
    // texel centre up to 3.5 pixels inside (docs/algorithm.md section 3, step 7).
    ivec2 clamped = clamp(base, ivec2(0), max(size - 2, ivec2(0)));
    vec2 f = c - vec2(clamped);
    // The footprint A B / C D; a tap outside a level narrower than 2 is
    // fetched clamped and never used.
    vec4 t[4];
    [[unroll]] for (int i = 0; i < 4; ++i) {
        t[i] = imageLoad(taps, ivec3(min(clamped + ivec2(i & 1, i >> 1), size - 1), up & 1));
    }
    uint a = uint(t[0].a), b = uint(t[1].a), cc = uint(t[2].a);
    // The parent's relation to each texel of the footprint (itself included).
    bool ab = (a & TAP_E) != 0u, ac = (a & TAP_S) != 0u, ad = (a & TAP_SE) != 0u;
    bool bc = (b & TAP_SW) != 0u, bd = (b & TAP_S) != 0u, cd = (cc & TAP_E) != 0u;
    ivec2 k = parent - clamped;  // the parent's place in the footprint, 0..1 each
    bvec4 same;
    if (k == ivec2(0, 0)) same = bvec4(true, ab, ac, ad);
    else if (k == ivec2(1, 0)) same = bvec4(ab, true, bc, bd);
    else if (k == ivec2(0, 1)) same = bvec4(ac, bc, true, cd);
    else same = bvec4(ad, bd, cd, true);
    vec4 parent_tap = k == ivec2(0, 0) ? t[0] : k == ivec2(1, 0) ? t[1] : k == ivec2(0, 1) ? t[2] : t[3];
    vec3 nearest = parent_tap.rgb;
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    bool all_valid = true;
    vec3 lo = vec3(3.0e38), hi = vec3(0.0);
    [[unroll]] for (int i = 0; i < 4; ++i) {
        ivec2 o = ivec2(i & 1, i >> 1);
        bool valid = same[i] && (uint(t[i].a) & TAP_VALUE) != 0u && all(lessThan(clamped + o, size));
        float w = valid ? (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y) : 0.0;
        all_valid = all_valid && valid;
        sum += w * t[i].rgb;
        weight += w;
        lo = valid ? min(lo, t[i].rgb) : lo;
        hi = valid ? max(hi, t[i].rgb) : hi;
    }
    // The weights sum to 1, extrapolating or not. An extrapolation (negative
    // weights) can overshoot where the values vary steeply: irradiance is never
    // negative, and it stays within one footprint range beyond the footprint.
    vec3 value;
    if (all_valid) {
        value = clamp(sum, max(lo - (hi - lo), vec3(0.0)), hi + (hi - lo));
    } else if (clamped != base) {
        value = nearest;  // no extrapolation from a partial footprint
    } else {
        // Renormalise over the texels that hold a value on the same surface;
        // the fractions are within 0..1 here, so the weights are non-negative.
        value = weight > 1e-6 ? sum / weight : nearest;
    }
    return vec4(value, parent_tap.a);
}

#endif
