#version 460
// The gather from a list of light patches (docs/algorithm.md sections 3 and
// 4): every eye-space patch evaluates every patch of the list its source
// wrote this frame, the N regular VPLs (regular_vpls/list.comp, method
// multires-gather) or the patches Basic ISR chose (isr/select.comp). The
// frame of the pass is multires/gather.glsl.
#extension GL_GOOGLE_include_directive : require
#include "multires/gather.glsl"

layout(set = 1, binding = GATHER_SOURCE_BINDING, std430) readonly buffer LightPatches {
    uint patch_count;
    uint pad0, pad1, pad2;
    LightPatch patches[];
};

void gather_patches(vec3 xi, vec3 ni, ivec2 p) {
    for (uint j = 0u; j < patch_count; ++j) {
        LightPatch lp = patches[j];
        if (lp.position_area.w <= 0.0) continue;  // an empty regular VPL
        // A list's normal.w is the patch's patch_level (regular_vpls/list.comp, isr/select.comp).
        add_patch(xi, ni, lp.position_area, lp.normal, lp.flux.rgb, int(lp.normal.w), true, 1.0);
    }
}
