// Level l of the geometry mips (docs/algorithm.md section 3, step 2) at texel
// p. Level 0 is the G-buffer itself: geometry_mips.comp writes mean position
// and normal for levels 1..L only (mip m of geo_mean and geo_normal is level
// m + 1), which saves two image stores per pixel. Include after declaring
// the samplers gbuffer_position and gbuffer_normal, and, unless
// GEO_LEVEL0_ONLY is defined (geometry_mips.comp), geo_mean and geo_normal.
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
// xyz: mean position; w: mean view depth.
vec4 geo_mean_at(ivec2 p, int level) {
    return level == 0 ? level0_mean(p) : texelFetch(geo_mean, p, level - 1);
}

// xyz: mean normal; w: coverage.
vec4 geo_normal_at(ivec2 p, int level) {
    return level == 0 ? level0_normal(p) : texelFetch(geo_normal, p, level - 1);
}
#endif

#endif
