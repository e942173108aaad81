#version 460
// Basic ISR patch selection (docs/algorithm.md section 4): from the dense base
// level b of the RSM quadtree, merge into the largest valid patches and append
// them to one list that every eye-space patch then gathers from. No CPU round
// trip: one dispatch over the base level.
//
// Each base texel looks at all its ancestors and takes the highest valid one
// (or itself: base-level patches always stand, they are the finest allowed).
// A valid patch has no invalid descendant (rsm_tree.comp), so every base
// texel under a chosen patch finds that same patch; empty quadrants inside it
// do not break the chain, since the highest valid ancestor is looked for, not
// the first gap. The base texel at the patch's first corner appends it, so
// every chosen patch is appended exactly once and the chosen patches
// partition the RSM.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0) uniform sampler2D rsm_position;  // quadtree (mip chain)
layout(set = 1, binding = 1) uniform sampler2D rsm_normal;
layout(set = 1, binding = 2) uniform sampler2D rsm_flux;
// The base level (methods::isr::base_level, from --isr-base).
layout(constant_id = 70) const int ISR_BASE_LEVEL = 0;

layout(set = 1, binding = 3, std430) buffer LightPatches {
    uint count;
    uint pad0, pad1, pad2;
    LightPatch patches[];
};

void main() {
    int base = ISR_BASE_LEVEL;
    int top = run.rsm_top_level;
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, textureSize(rsm_position, base)))) return;
    int level = base;
    ivec2 p = t;
    for (int l = base + 1; l <= top; ++l) {
        ivec2 a = t >> (l - base);
        if (texelFetch(rsm_normal, a, l).w == PATCH_VALID) {
            level = l;
            p = a;
        }
    }
    if ((p << (level - base)) != t) return;  // not the patch's first base texel
    vec4 position = texelFetch(rsm_position, p, level);
    if (position.w <= 0.0) return;  // saw nothing
    uint slot = atomicAdd(count, 1u);
    vec4 normal = texelFetch(rsm_normal, p, level);
    patches[slot] = LightPatch(position, vec4(normal.xyz, float(patch_level(level, normal.w))),
                               texelFetch(rsm_flux, p, level));
}
