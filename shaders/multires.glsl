// The multiresolution illumination buffer's patch test (docs/algorithm.md section 3,
// step 4), shared by the stenciled refinement and the unstenciled gather.
#ifndef MULTIRES_GLSL
#define MULTIRES_GLSL

// Texel (level, p) is a patch iff it has geometry, is not split, and is at the
// coarsest level or its parent is split. A parent outside the coarser level's
// extent (image sizes that are not multiples of 2^L) counts as split.
bool is_patch(usampler2D flags, int level, int coarsest, ivec2 p) {
    uint f = texelFetch(flags, p, level).r;
    if ((f & GEO_HAS_GEOMETRY) == 0u || (f & GEO_SPLIT) != 0u) return false;
    if (level == coarsest) return true;
    ivec2 parent = p >> 1;
    if (any(greaterThanEqual(parent, textureSize(flags, level + 1)))) return true;
    return (texelFetch(flags, parent, level + 1).r & GEO_SPLIT) != 0u;
}

#endif
