#version 460
// Pass `light-tree-pack` (HISR, docs/algorithm.md section 4): copies the RSM
// quadtree's mip chains into one storage buffer, a LightPatch per node, so the
// per-fragment traversal reads a node with one contiguous load instead of
// three texel fetches from three mip chains. Each node's flux.a (the summed
// solid angle, which HISR does not read) becomes its squared reach
// (hisr_reach in hisr/hisr.glsl): the split test is one comparison per node, and
// the per-node bound is computed once per frame instead of per fragment.
//
// Order: depth-major from the root. Depth d (2^d x 2^d patches, RSM mip
// top - d) starts at node (4^d - 1) / 3, row-major inside: node (x, y) of depth
// d is (4^d - 1) / 3 + y 2^d + x. Only depths down to the max depth D are
// packed (nodes there never split, so none deeper is read). One invocation per
// node, laid out 2^D wide.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "light_types.glsl"
#include "hisr/hisr.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0) uniform sampler2D rsm_position;  // quadtree (mip chain)
layout(set = 1, binding = 1) uniform sampler2D rsm_normal;
layout(set = 1, binding = 2) uniform sampler2D rsm_flux;
layout(set = 1, binding = 3, std430) writeonly buffer LightPatches {
    uint count;  // nodes packed, (4^(D+1) - 1) / 3
    uint pad0, pad1, pad2;
    LightPatch nodes[];
};

void main() {
    int top = run.rsm_top_level;  // mip of the root
    int w = 1 << HISR_MAX_DEPTH;  // 2^D patches per side at the max depth
    int i = int(gl_GlobalInvocationID.y) * w + int(gl_GlobalInvocationID.x);
    int total = (4 * w * w - 1) / 3;
    if (gl_GlobalInvocationID.x >= uint(w) || i >= total) return;
    if (i == 0) count = uint(total);
    int node = i;
    int d = 0;
    while (node >= 1 << (2 * d)) {
        node -= 1 << (2 * d);
        ++d;
    }
    int side = 1 << d;
    ivec2 xy = ivec2(node % side, node / side);
    int mip = top - d;
    LightPatch lp = LightPatch(texelFetch(rsm_position, xy, mip), texelFetch(rsm_normal, xy, mip),
                               texelFetch(rsm_flux, xy, mip));
    lp.flux.a = hisr_reach(lp, ivec3(xy, d));
    nodes[i] = lp;
}
