#version 460
// Pass `vpl-list` (docs/algorithm.md section 4.1): the N regular VPLs
// written once per frame into one buffer, VPL j at entry j (an empty one with
// zero area, which the gather skips), so every eye-space patch reads each VPL
// with one load of the same address instead of three texel fetches from a
// mip level (multires/gather_list.frag).
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0) uniform sampler2D rsm_position;  // quadtree (mip chain)
layout(set = 1, binding = 1) uniform sampler2D rsm_normal;
layout(set = 1, binding = 2) uniform sampler2D rsm_flux;
layout(set = 1, binding = 3, std430) writeonly buffer LightPatches {
    uint count;  // N: every entry, empty or not
    uint pad0, pad1, pad2;
    LightPatch vpls[];
};

#include "regular_vpls/regular_vpls.glsl"

void main() {
    int side = VPL_SIDE;
    ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(xy, ivec2(side)))) return;
    int j = xy.y * side + xy.x;
    if (j == 0) count = uint(side * side);
    vec4 pos, nrm;
    vec3 flux;
    if (regular_vpl(j, pos, nrm, flux)) {
        vpls[j] = LightPatch(pos, nrm, vec4(flux, 0.0));  // nrm.w: patch_level
    } else {
        vpls[j] = LightPatch(vec4(0.0), vec4(0.0), vec4(0.0));
    }
}
