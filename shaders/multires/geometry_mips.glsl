// One level l >= 1 of the geometry mipmaps (docs/algorithm.md section 3, steps
// 2-4), shared by multires/geometry_level_one.frag (level 1, from the G-buffer) and
// multires/geometry_mips.frag (levels 2..L, from level l - 1). Level 0 is the G-buffer
// itself and is not stored (multires/geo_levels.glsl); every chain holds levels 1..L
// (mip m is level m + 1). Per texel: mean position and view depth, mean normal
// and coverage, the depth and normal-component ranges, and the flags smooth /
// split.
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
//
// Full-screen draws over each level into its mips as five color attachments,
// not compute dispatches: CPU drivers write attachments a tile at a time, and
// five storage-image stores per texel were most of level 1's cost.
#ifndef GEOMETRY_MIPS_GLSL
#define GEOMETRY_MIPS_GLSL

layout(location = 0) out vec4 out_mean;    // xyz: mean position; w: mean view depth
layout(location = 1) out vec4 out_normal;  // xyz: mean normal (unit); w: coverage
layout(location = 2) out vec4 out_min;     // x: min depth; yzw: min normal components
layout(location = 3) out vec4 out_max;     // x: max depth; yzw: max normal components
layout(location = 4) out uint out_flags;

const float BIG = 3.0e38;

bool smooth_ranges(vec4 lo, vec4 hi) {
    bool depth_ok = (hi.x - lo.x) < run.depth_threshold * lo.x;
    bool normal_ok = length(hi.yzw - lo.yzw) < run.normal_chord;
    return depth_ok && normal_ok;
}

// Writes a texel from its children's coverage-weighted sums and its ranges.
// `split_below`: a texel of level l - 1 in the 4x4 block around its children
// splits (never at level 1: level 0 does not split).
void write_texel(vec4 mean, vec3 normal, float coverage, vec4 lo, vec4 hi, bool split_below) {
    uint flags = 0u;
    if (coverage > 0.0) {
        mean /= coverage;
        // Opposite normals (two sides of a thin sheet) can cancel: no direction then.
        normal = dot(normal, normal) > 1e-12 ? normalize(normal) : vec3(0.0);
        flags |= GEO_HAS_GEOMETRY;
        // Coverage is a mean of 0s and 1s over 4^l pixels: exact in binary.
        if (coverage == 4.0 && smooth_ranges(lo, hi)) flags |= GEO_SMOOTH;
        if ((flags & GEO_SMOOTH) == 0u || split_below) flags |= GEO_SPLIT;
    }
    out_mean = mean;
    out_normal = vec4(normal, coverage * 0.25);
    out_min = lo;
    out_max = hi;
    out_flags = flags;
}

#endif
