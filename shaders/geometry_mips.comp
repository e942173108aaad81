#version 460
// One level l >= 1 of the geometry mipmaps (docs/algorithm.md section 3, steps
// 2-4): merges 2x2 texels of level l - 1. Level 0 is the G-buffer itself and
// is not stored (geo_levels.glsl): level 1 reads the G-buffer, and every
// chain holds levels 1..L (mip m is level m + 1). Per texel: mean position
// and view depth, mean normal and coverage, the depth and normal-component
// ranges, and the flags smooth / split.
//
// Discontinuities on texel borders: every texel's range covers its footprint
// plus a one-pixel ring, so an edge lying exactly on a border is seen by the
// texels on both sides; level 0 needs none (it is always smooth). Level 1
// takes its ranges straight from the G-buffer's 4x4 pixels (its 2x2 children
// and their ring), each level above merges its children's ranges (the union
// of their footprints and rings is its footprint and ring).
//
// 2:1 balance: a texel splits if it is not smooth, or if any texel of level
// l - 1 in the 4x4 block around its children (its children and the ring of
// their neighbours) splits. So no leaf is adjacent to a leaf two levels finer.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;  // xyz world, w view depth (0: background)
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
// Level l - 1 (unused at level 1, which reads the G-buffer).
layout(set = 1, binding = 2, rgba32f) readonly uniform image2D src_mean;    // xyz: mean position; w: mean view depth
layout(set = 1, binding = 3, rgba32f) readonly uniform image2D src_normal;  // xyz: mean normal (unit); w: coverage
layout(set = 1, binding = 4, rgba32f) readonly uniform image2D src_min;     // x: min depth; yzw: min normal components
layout(set = 1, binding = 5, rgba32f) readonly uniform image2D src_max;     // x: max depth; yzw: max normal components
layout(set = 1, binding = 6, r32ui) readonly uniform uimage2D src_flags;
// Level l.
layout(set = 1, binding = 7, rgba32f) writeonly uniform image2D dst_mean;
layout(set = 1, binding = 8, rgba32f) writeonly uniform image2D dst_normal;
layout(set = 1, binding = 9, rgba32f) writeonly uniform image2D dst_min;
layout(set = 1, binding = 10, rgba32f) writeonly uniform image2D dst_max;
layout(set = 1, binding = 11, r32ui) writeonly uniform uimage2D dst_flags;

// Level 1 (reads the G-buffer) and the levels above (read level l - 1) are
// separate pipelines: CPU drivers run both sides of a branch under a lane
// mask, so a branch on the level would cost every texel the reads of both.
layout(constant_id = 0) const bool LEVEL_ONE = false;

// Level 0 as the other passes read it (levels above come from src_* here).
#define GEO_LEVEL0_ONLY
#include "geo_levels.glsl"

const float BIG = 3.0e38;

bool smooth_ranges(vec4 lo, vec4 hi) {
    bool depth_ok = (hi.x - lo.x) < run.refine.x * lo.x;
    bool normal_ok = length(hi.yzw - lo.yzw) < run.refine.y;
    return depth_ok && normal_ok;
}

// Level 1 from the G-buffer's 4x4 pixels around texel p (its 2x2 children
// and their one-pixel ring): the children's sums and the ranges over the
// pixels with geometry. Each pixel is fetched once and unconditionally
// (clamped, then masked): fetches under a condition cost CPU drivers as much
// as taken ones, and the children's fetches are the block's inner 2x2.
void level_one(ivec2 p, inout vec4 mean, inout vec3 normal, inout float coverage, inout vec4 lo, inout vec4 hi) {
    ivec2 size = ivec2(run.size.xy);
    [[unroll]] for (int dy = -1; dy <= 2; ++dy) {
        [[unroll]] for (int dx = -1; dx <= 2; ++dx) {
            ivec2 q = 2 * p + ivec2(dx, dy);
            bool inside = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size));
            ivec2 qc = clamp(q, ivec2(0), size - 1);
            vec4 qp = texelFetch(gbuffer_position, qc, 0);
            vec3 qn = texelFetch(gbuffer_normal, qc, 0).xyz;
            if (inside && qp.w > 0.0) {
                lo = min(lo, vec4(qp.w, qn));
                hi = max(hi, vec4(qp.w, qn));
            }
            // The children (always inside: qc = q), in the order of the
            // levels above; the compiler merges these fetches with the above.
            if (dx >= 0 && dx <= 1 && dy >= 0 && dy <= 1) {
                vec4 cn = level0_normal(qc);
                mean += cn.w * level0_mean(qc);
                normal += cn.w * cn.xyz;
                coverage += cn.w;
            }
        }
    }
}

void coarser_level(ivec2 p) {
    vec4 mean = vec4(0.0);
    vec3 normal = vec3(0.0);
    float coverage = 0.0;
    vec4 lo = vec4(BIG), hi = vec4(-BIG);
    if (LEVEL_ONE) {
        level_one(p, mean, normal, coverage, lo, hi);
    } else {
        for (int i = 0; i < 4; ++i) {
            ivec2 c = 2 * p + ivec2(i & 1, i >> 1);
            vec4 cn = imageLoad(src_normal, c);
            mean += cn.w * imageLoad(src_mean, c);
            normal += cn.w * cn.xyz;
            coverage += cn.w;
            lo = min(lo, imageLoad(src_min, c));
            hi = max(hi, imageLoad(src_max, c));
        }
    }
    uint flags = 0u;
    if (coverage > 0.0) {
        mean /= coverage;
        // Opposite normals (two sides of a thin sheet) can cancel: no direction then.
        normal = dot(normal, normal) > 1e-12 ? normalize(normal) : vec3(0.0);
        flags |= GEO_HAS_GEOMETRY;
        // Coverage is a mean of 0s and 1s over 4^l pixels: exact in binary.
        if (coverage == 4.0 && smooth_ranges(lo, hi)) flags |= GEO_SMOOTH;
        bool split = (flags & GEO_SMOOTH) == 0u;
        ivec2 below = imageSize(src_flags);
        // Level 0 never splits: level 1 has no finer splits to look at.
        for (int dy = -1; dy <= 2 && !split && !LEVEL_ONE; ++dy) {
            for (int dx = -1; dx <= 2; ++dx) {
                ivec2 q = 2 * p + ivec2(dx, dy);
                if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, below))) continue;
                if ((imageLoad(src_flags, q).r & GEO_SPLIT) != 0u) {
                    split = true;
                    break;
                }
            }
        }
        if (split) flags |= GEO_SPLIT;
    }
    imageStore(dst_mean, p, mean);
    imageStore(dst_normal, p, vec4(normal, coverage * 0.25));
    imageStore(dst_min, p, lo);
    imageStore(dst_max, p, hi);
    imageStore(dst_flags, p, uvec4(flags));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(dst_flags)))) return;
    coarser_level(p);
}
