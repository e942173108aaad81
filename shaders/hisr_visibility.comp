#version 460
// Pass `hisr-visibility` (HISR with --visibility voxels and shared tile
// visibility, docs/algorithm.md section 5, "Tile-shared visibility"): the
// entries of a tile's cut are the same for every receiver in it, so their
// visibility is marched once from each of the finest tile's four corner
// pixels instead of once per receiver: the three levels' evaluate entries,
// and the finest level's traverse entries toward their walk's root. The
// gather interpolates the four (traverse_cut_shared).
// One invocation per (slot, finest tile): x the slot among the three
// levels' capacities (coarsest level first, as the gather sums them), y the
// finest tile. The four corners are the G-buffer pixels at the tile's
// corners (the far ones are the next tiles' first pixels, clamped to the
// image), so neighbouring tiles march from the same points.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "light_types.glsl"
#include "visibility.glsl"
#include "hisr.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;  // xyz world, w view depth (0: background)
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 1, binding = 2, std430) readonly buffer LightTree {
    uint node_count;
    uint pad0, pad1, pad2;
    LightPatch nodes[];  // the packed tree (light_tree_pack.comp)
};
layout(set = 1, binding = 3, std430) buffer HisrCut {
    HisrCutHeader header;
    uint cut[];  // per level counts, then per level entries, then the visibilities (shared.glsl)
};
#define GEO_LEVEL0_ONLY
#include "geo_levels.glsl"

void main() {
    uint slot = gl_GlobalInvocationID.x;
    uint t = gl_GlobalInvocationID.y;
    uvec4 finest = header.tiles[0];
    if (slot >= header.visibility.y || t >= finest.x * finest.y) return;
    // The slot's level c (coarsest first) and entry i there.
    int c = HISR_CUT_LEVELS - 1;
    uint i = slot;
    while (c > 0 && i >= header.capacity[c]) {
        i -= header.capacity[c];
        --c;
    }
    uvec2 tile = uvec2(t % finest.x, t / finest.x);
    // A finer tile overflows where a coarser one does (hisr_cut.comp), so the
    // finest tile's count says whether the gather reads these at all.
    if (cut[finest.w + t] == HISR_CUT_OVERFLOW) return;
    uvec2 tc = tile >> uint(c);
    uint at = tc.y * header.tiles[c].x + tc.x;
    uint counts = cut[header.tiles[c].w + at];
    uint evaluate = counts & 0xffffu;
    // Evaluate entries from the front of the range; the finest level's
    // traverse entries from its back.
    if (i >= evaluate && (c > 0 || i < header.capacity[0] - (counts >> 16))) return;
    uint e = cut[header.entries[1 + c] + at * header.capacity[c] + i];
    LightPatch lp = nodes[i < evaluate ? e : uint(node_index(cut_node(e)))];
    int side = 1 << finest.z;
    ivec2 origin = ivec2(tile) * side;
    vec4 v = vec4(1.0);
    for (int k = 0; k < 4; ++k) {
        ivec2 px = min(origin + side * ivec2(k & 1, k >> 1), ivec2(run.output_size) - 1);
        vec4 x = level0_mean(px);
        // A corner without geometry is never used (the gather gives it no weight).
        if (x.w > 0.0) v[k] = voxel_visibility(x.xyz, level0_normal(px).xyz, lp.position_area.xyz, lp.normal.xyz);
    }
    cut[header.visibility.x + t * header.visibility.y + slot] = packUnorm4x8(v);
}
