#version 460
// Upsampling of the multiresolution illumination buffer (docs/algorithm.md section
// 3, step 7), one level per dispatch; the push into level 0, which writes the
// indirect image, is multires/upsample_level0.frag.
//
// PULL (levels 1..L, finest first): texels without a value that have children
// with values take their mean, so coarse neighbours of fine regions carry the
// fine values. PUSH (levels L-1..1): texels without a value take their parent's
// value (nearest) or bilinear weights over the four nearest coarser texels,
// renormalised over those that hold a value and are on the same surface as the
// parent (no depth or normal discontinuity): push_value in multires/upsample.glsl.
// The dispatch that finalises a level (the pull of L, every push) writes its
// taps (multires/upsample.glsl), which the push into the level below reads.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, rgba32f) uniform image2DArray illumination;
layout(set = 1, binding = 1) uniform sampler2D geo_mean;    // levels 1..L; w: mean view depth
layout(set = 1, binding = 2) uniform sampler2D geo_normal;  // levels 1..L; w: coverage
layout(set = 1, binding = 3, rgba32f) uniform image2DArray taps;

// One pipeline per kind of dispatch, specialised: CPU drivers run both sides
// of a branch under a lane mask, so a branch on a push constant would cost
// every invocation the code of every kind. INTERPOLATE comes from the
// settings the pass is built with (new settings rebuild the passes).
layout(constant_id = 10) const bool PULL = false;  // pull into `level` from level - 1; else push from level + 1
layout(constant_id = 11) const bool WRITE_TAPS = false;  // a pull that finalises `level` (L); pushes always do
layout(constant_id = 12) const bool INTERPOLATE = true;

layout(push_constant) uniform Push { int level; };

#include "multires/upsample.glsl"

// Same surface: view depths within twice the refinement's relative depth
// threshold and normals within twice its angle, both texels with geometry.
bool same_surface(vec4 mean_a, vec4 normal_a, vec4 mean_b, vec4 normal_b) {
    float depth_ok = abs(mean_a.w - mean_b.w) - 2.0 * run.depth_threshold * min(mean_a.w, mean_b.w);
    float chord = length(normal_a.xyz - normal_b.xyz);
    return normal_a.w > 0.0 && normal_b.w > 0.0 && depth_ok <= 0.0 && chord <= 2.0 * run.normal_chord;
}

// Writes the taps of texel p of `level` (final value v, geometry mean and
// normal). Neighbours outside the level are never on the same surface; each
// is fetched unconditionally (clamped, then masked): CPU drivers pay for a
// fetch under a condition as for a taken one.
void store_tap(ivec2 p, vec4 v, vec4 mean, vec4 normal) {
    ivec2 size = level_size(level);
    const ivec2 offsets[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(-1, 1));
    uint bits = (v.a > 0.0 && normal.w > 0.0 ? TAP_VALUE : 0u) | (normal.w == 1.0 ? TAP_FULL : 0u);
    [[unroll]] for (int i = 0; i < 4; ++i) {
        ivec2 q = p + offsets[i];
        ivec2 qc = clamp(q, ivec2(0), size - 1);
        bool same = same_surface(mean, normal, texelFetch(geo_mean, qc, level - 1), texelFetch(geo_normal, qc, level - 1));
        if (q == qc && same) bits |= TAP_E << i;
    }
    imageStore(taps, ivec3(p, level & 1), vec4(v.rgb, float(bits)));
}

void pull_texel(ivec2 p) {
    vec4 v = imageLoad(illumination, ivec3(p, level));
    if (v.a <= 0.0) {
        vec3 sum = vec3(0.0);
        float n = 0.0;
        for (int i = 0; i < 4; ++i) {
            vec4 c = imageLoad(illumination, ivec3(2 * p + ivec2(i & 1, i >> 1), level - 1));
            if (c.a > 0.0) {
                sum += c.rgb;
                n += 1.0;
            }
        }
        if (n > 0.0) {
            v = vec4(sum / n, PULLED);
            imageStore(illumination, ivec3(p, level), v);
        }
    }
    if (WRITE_TAPS) store_tap(p, v, texelFetch(geo_mean, p, level - 1), texelFetch(geo_normal, p, level - 1));
}

void push_texel(ivec2 p) {
    vec4 v = imageLoad(illumination, ivec3(p, level));
    vec4 mean = texelFetch(geo_mean, p, level - 1);
    vec4 normal = texelFetch(geo_normal, p, level - 1);
    // Pushed values go only to the taps: nothing reads them from the buffer,
    // and a store per texel is costly on CPU drivers.
    if (v.a <= 0.0 && normal.w > 0.0) v = vec4(push_value(p, level).rgb, PUSHED);
    store_tap(p, v, mean, normal);
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
