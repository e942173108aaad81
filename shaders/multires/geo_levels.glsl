// Level l of the geometry mips (docs/algorithm.md section 3, step 2) at texel
// p. Level 0 is the G-buffer itself: geometry_mips.comp writes levels 1..L
// only (mip m of every geo_* chain is level m + 1), which saves a dispatch
// and three image stores per pixel. Include after declaring the samplers
// gbuffer_position and gbuffer_normal and, unless GEO_LEVEL0_ONLY is defined
// (geometry_mips.comp), those of the chains a shader reads: geo_mean and
// geo_normal unless GEO_NO_MEANS is defined, geo_flags if GEO_FLAGS is.
#ifndef GEO_LEVELS_GLSL
#define GEO_LEVELS_GLSL

// xyz: position; w: view depth (0: no geometry).
vec4 level0_mean(ivec2 p) { return texelFetch(gbuffer_position, p, 0); }

// xyz: unit normal (renormalised: the G-buffer holds 16-bit floats); w:
// coverage, 1 where there is geometry.
vec4 level0_normal(ivec2 p) {
    if (texelFetch(gbuffer_position, p, 0).w <= 0.0) return vec4(0.0);
    return vec4(normalize(texelFetch(gbuffer_normal, p, 0).xyz), 1.0);
}

#ifndef GEO_LEVEL0_ONLY
#ifndef GEO_NO_MEANS
// xyz: mean position; w: mean view depth.
vec4 geo_mean_at(ivec2 p, int level) {
    return level == 0 ? level0_mean(p) : texelFetch(geo_mean, p, level - 1);
}

// xyz: mean normal; w: coverage.
vec4 geo_normal_at(ivec2 p, int level) {
    return level == 0 ? level0_normal(p) : texelFetch(geo_normal, p, level - 1);
}
#endif

#ifdef GEO_FLAGS
// GEO_* flags; level 0 is always smooth and never splits.
uint geo_flags_at(ivec2 p, int level) {
    if (level == 0) return level0_mean(p).w > 0.0 ? GEO_HAS_GEOMETRY | GEO_SMOOTH : 0u;
    return texelFetch(geo_flags, p, level - 1).r;
}

// The patch test (docs/algorithm.md section 3, step 4), shared by the
// stenciled refinement and the unstenciled gather: texel (level, p) is a
// patch iff it has geometry, is not split, and is at the coarsest level or
// its parent is split. A parent outside the coarser level's extent (image
// sizes that are not multiples of 2^L) counts as split.
bool is_patch(int level, int coarsest, ivec2 p) {
    uint f = geo_flags_at(p, level);
    if ((f & GEO_HAS_GEOMETRY) == 0u || (f & GEO_SPLIT) != 0u) return false;
    if (level == coarsest) return true;
    ivec2 parent = p >> 1;
    // Level + 1 >= 1: mip level of the chain.
    if (any(greaterThanEqual(parent, textureSize(geo_flags, level)))) return true;
    return (texelFetch(geo_flags, parent, level).r & GEO_SPLIT) != 0u;
}
#endif
#endif

#endif
