#version 460
// Upsampling of the multiresolution illumination buffer (docs/algorithm.md section
// 3, step 7), one level per dispatch.
//
// Texel alpha: 1 = a patch the gather shaded; 0.5 = pulled (the mean of its
// children, for texels split into finer patches); 0.75 = pushed (from the
// coarser level); 0 = no value (yet).
//
// PULL (levels 1..L, finest first): texels without a value that have children
// with values take their mean, so coarse neighbours of fine regions carry the
// fine values. PUSH (levels L-1..0): texels without a value take their parent's
// value (nearest) or bilinear weights over the four nearest coarser texels,
// renormalised over those that hold a value and are on the same surface (no
// depth or normal discontinuity). Level 0 is written to the indirect image
// (and its pushed texels only there).
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, rgba32f) uniform image2DArray illumination;
layout(set = 1, binding = 1) uniform sampler2D geo_mean;    // levels 1..L; w: mean view depth
layout(set = 1, binding = 2) uniform sampler2D geo_normal;  // levels 1..L; w: coverage
layout(set = 1, binding = 3, rgba32f) writeonly uniform image2D indirect;
layout(set = 1, binding = 4) uniform sampler2D gbuffer_position;  // level 0
layout(set = 1, binding = 5) uniform sampler2D gbuffer_normal;
#include "geo_levels.glsl"

// One pipeline per kind of dispatch, specialised: CPU drivers run both sides
// of a branch under a lane mask, so a branch on a push constant would cost
// every invocation the code of every kind. INTERPOLATE comes from the
// settings the pass is built with (new settings rebuild the passes).
layout(constant_id = 0) const bool PULL = false;        // pull into `level` from level - 1; else push from level + 1
layout(constant_id = 1) const bool LEVEL_ZERO = false;  // push into level 0 (writes `indirect`)
layout(constant_id = 2) const bool INTERPOLATE = true;

layout(push_constant) uniform Push { int level; };

const float PULLED = 0.5;
const float PUSHED = 0.75;

ivec2 level_size(int l) { return ivec2(run.size.xy) >> l; }

bool inside(ivec2 q, int l) { return all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, level_size(l))); }

void pull_texel(ivec2 p) {
    vec4 v = imageLoad(illumination, ivec3(p, level));
    if (v.a > 0.0) return;
    vec3 sum = vec3(0.0);
    float n = 0.0;
    for (int i = 0; i < 4; ++i) {
        vec4 c = imageLoad(illumination, ivec3(2 * p + ivec2(i & 1, i >> 1), level - 1));
        if (c.a > 0.0) {
            sum += c.rgb;
            n += 1.0;
        }
    }
    if (n > 0.0) imageStore(illumination, ivec3(p, level), vec4(sum / n, PULLED));
}

// Same surface: view depths within twice the refinement's relative depth
// threshold and normals within twice its angle.
bool same_surface(vec4 mean_a, vec3 n_a, vec4 mean_b, vec3 n_b) {
    float depth_ok = abs(mean_a.w - mean_b.w) - 2.0 * run.refine.x * min(mean_a.w, mean_b.w);
    float chord = length(n_a - n_b);
    return depth_ok <= 0.0 && chord <= 2.0 * run.refine.y;
}

// `mean` and `n`: this texel's mean position and normal.
vec3 interpolate(ivec2 p, vec4 mean, vec3 n, vec3 fallback) {
    int up = level + 1;
    ivec2 size = level_size(up);
    // Texel centre in the coarser level's texel coordinates.
    vec2 c = (vec2(p) + 0.5) * 0.5 - 0.5;
    ivec2 base = ivec2(floor(c));
    // At the image border the 2x2 footprint would leave the level: keep it
    // inside, which turns the weights into a linear extrapolation (fractions
    // outside 0..1). Without this, border pixels would repeat the value of a
    // texel centre up to 3.5 pixels inside (docs/algorithm.md section 3, step 7).
    ivec2 clamped = clamp(base, ivec2(0), max(size - 2, ivec2(0)));
    vec2 f = c - vec2(clamped);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    bool all_valid = true;
    vec3 lo = vec3(3.0e38), hi = vec3(0.0);
    for (int i = 0; i < 4; ++i) {
        ivec2 o = ivec2(i & 1, i >> 1);
        ivec2 q = clamped + o;
        bool valid = inside(q, up);
        vec4 v = vec4(0.0);
        if (valid) {
            v = imageLoad(illumination, ivec3(q, up));
            // Level up >= 1: straight from the chains (mip up - 1).
            vec4 qn = texelFetch(geo_normal, q, up - 1);
            valid = v.a > 0.0 && qn.w > 0.0 && same_surface(mean, n, texelFetch(geo_mean, q, up - 1), qn.xyz);
        }
        if (!valid) {
            all_valid = false;
            continue;
        }
        float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        sum += w * v.rgb;
        weight += w;
        lo = min(lo, v.rgb);
        hi = max(hi, v.rgb);
    }
    // The weights sum to 1, extrapolating or not. An extrapolation (negative
    // weights) can overshoot where the values vary steeply: irradiance is never
    // negative, and it stays within one footprint range beyond the footprint.
    if (all_valid) return clamp(sum, max(lo - (hi - lo), vec3(0.0)), hi + (hi - lo));
    if (clamped != base) return fallback;  // no extrapolation from a partial footprint
    // Renormalise over the texels that hold a value on the same surface; the
    // fractions are within 0..1 here, so the weights are non-negative.
    return weight > 1e-6 ? sum / weight : fallback;
}

void push_texel(ivec2 p) {
    vec4 v = imageLoad(illumination, ivec3(p, level));
    // This texel's geometry, once.
    vec4 mean, normal;
    if (LEVEL_ZERO) {
        mean = level0_mean(p);
        normal = level0_normal(p);
    } else {
        mean = texelFetch(geo_mean, p, level - 1);
        normal = texelFetch(geo_normal, p, level - 1);
    }
    bool geometry = normal.w > 0.0;
    if (v.a <= 0.0 && geometry) {
        ivec2 parent = p >> 1;
        vec3 nearest = inside(parent, level + 1) ? imageLoad(illumination, ivec3(parent, level + 1)).rgb : vec3(0.0);
        v = vec4(INTERPOLATE ? interpolate(p, mean, normal.xyz, nearest) : nearest, PUSHED);
        // Level 0's pushed values go only to `indirect`: nothing reads them
        // from the buffer, and a store per pixel is costly on CPU drivers.
        if (!LEVEL_ZERO) imageStore(illumination, ivec3(p, level), v);
    }
    if (LEVEL_ZERO) imageStore(indirect, p, vec4(geometry ? v.rgb : vec3(0.0), 1.0));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (!inside(p, level)) return;
    if (PULL) {
        pull_texel(p);
    } else {
        push_texel(p);
    }
}
