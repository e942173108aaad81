#version 460
// Pass `hisr-cut` (HISR, docs/algorithm.md section 4.4): one invocation per
// eye-space tile of 2^K x 2^K pixels finds the part of the light-tree
// traversal that every receiver in the tile would make alike, so that the
// gather's fragments start from a shared, coherent list instead of each
// walking the tree from the roots.
//
// Every receiver of the tile (a patch mean of levels <= K: a mean of the
// tile's G-buffer positions) lies in the box of the tile's positions. For a
// node with squared reach R (hisr/hisr.glsl), and the box's nearest and farthest
// squared distances n <= |V_ij|^2 <= f:
//   f <= R (and above the max depth): every receiver splits it; its children
//     are examined here;
//   n > R, or at the max depth: no receiver splits it; entry "evaluate";
//   otherwise receivers disagree; entry "traverse", walked per fragment.
// So each fragment makes the same decisions as a traversal from the roots.
// The box is padded by a little more than float rounding so that a receiver
// on its surface is decided alike too.
//
// One dispatch for the finest tiles' boxes (BOXES), then one per chained
// level (HISR_CUT_LEVELS, coarsest first), one invocation per tile,
// depth-first without a stack, entries written in traversal order (so the
// gather's sums come in the same order every frame). A finer tile lies
// inside its parent, so its box does too, and its cut only refines the
// parent's traverse entries. A tile whose list does not fit, or whose
// parent's did not, is marked HISR_CUT_OVERFLOW and its fragments traverse
// from the roots (same result, slower).
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "light_types.glsl"
#include "hisr/hisr.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;  // xyz world, w view depth (0: background)
layout(set = 1, binding = 1, std430) readonly buffer LightTree {
    uint node_count;
    uint pad0, pad1, pad2;
    LightPatch nodes[];  // the packed tree (hisr/tree_pack.comp)
};
layout(set = 1, binding = 2, std430) buffer HisrCut {
    HisrCutHeader header;
    uint cut[];  // per level counts, then per level entries (shared.glsl)
};

layout(push_constant) uniform Push {
    HisrCutHeader layout_;  // what the header will hold
    int level;              // the cut level c this dispatch makes
};

// BOXES: the dispatch before the cuts, one invocation per finest tile, writes
// the (unpadded) box of its positions; the cut dispatches take a tile's box as
// the union of its finest tiles' boxes (min and max are exact, so it is the
// box of its positions), so each G-buffer position is read once, not once per
// level (the coarsest level's few invocations each read 4096 of them).
layout(constant_id = 32) const bool BOXES = false;

const vec3 EMPTY_LO = vec3(3.0e38);
const vec3 EMPTY_HI = vec3(-3.0e38);

// Finest tile t's box, at entries.x: lo.xyz, pad, hi.xyz, pad (float bits).
uint box_at(uint t) { return layout_.entries.x + 8u * t; }

void write_finest_box(ivec2 tile) {
    int side = 1 << layout_.tiles[0].z;
    ivec2 origin = tile * side;
    ivec2 end = min(origin + side, ivec2(run.output_size));
    vec3 lo = EMPTY_LO, hi = EMPTY_HI;
    for (int y = origin.y; y < end.y; ++y) {
        for (int x = origin.x; x < end.x; ++x) {
            vec4 p = texelFetch(gbuffer_position, ivec2(x, y), 0);
            if (p.w <= 0.0) continue;
            lo = min(lo, p.xyz);
            hi = max(hi, p.xyz);
        }
    }
    uint at = box_at(uint(tile.y) * layout_.tiles[0].x + uint(tile.x));
    for (int k = 0; k < 3; ++k) {
        cut[at + k] = floatBitsToUint(lo[k]);
        cut[at + 4 + k] = floatBitsToUint(hi[k]);
    }
}

// The box of tile `tile` of this level, padded (see above); lo.x > hi.x if it
// has no positions.
void tile_box(ivec2 tile, out vec3 lo, out vec3 hi) {
    int n = 1 << level;  // finest tiles per side
    ivec2 origin = tile * n;
    ivec2 end = min(origin + n, ivec2(layout_.tiles[0].xy));
    lo = EMPTY_LO;
    hi = EMPTY_HI;
    for (int y = origin.y; y < end.y; ++y) {
        for (int x = origin.x; x < end.x; ++x) {
            uint at = box_at(uint(y) * layout_.tiles[0].x + uint(x));
            lo = min(lo, uintBitsToFloat(uvec3(cut[at], cut[at + 1], cut[at + 2])));
            hi = max(hi, uintBitsToFloat(uvec3(cut[at + 4], cut[at + 5], cut[at + 6])));
        }
    }
    vec3 m = max(abs(lo), abs(hi));
    float pad = 1e-5 * max(m.x, max(m.y, m.z)) + 1e-4 * length(max(hi - lo, vec3(0.0)));
    lo -= pad;
    hi += pad;
}

void main() {
    uvec4 lv = layout_.tiles[level];
    uint capacity = layout_.capacity[level];
    ivec2 tile = ivec2(gl_GlobalInvocationID.xy);
    if (BOXES) {
        if (all(lessThan(tile, ivec2(layout_.tiles[0].xy)))) write_finest_box(tile);
        return;
    }
    if (level == 0 && tile == ivec2(0)) header = layout_;
    if (any(greaterThanEqual(tile, ivec2(lv.xy)))) return;
    uint t = uint(tile.y) * lv.x + uint(tile.x);
    uint base = layout_.entries[1 + level] + t * capacity;
    // Roots: the start depth's nodes for the coarsest level, else the parent
    // tile's traverse entries (its evaluate entries hold for this tile too).
    int start = HISR_START_DEPTH;
    int side = 1 << start;
    uint roots = uint(side * side);
    uint parent_last = 0u;
    if (level + 1 < HISR_CUT_LEVELS) {
        uvec4 lp = layout_.tiles[level + 1];
        uvec2 pt = uvec2(tile >> 1);
        uint p = pt.y * lp.x + pt.x;
        uint counts = cut[lp.w + p];
        if (counts == HISR_CUT_OVERFLOW) {
            cut[lv.w + t] = HISR_CUT_OVERFLOW;
            return;
        }
        roots = counts >> 16;
        uint parent_capacity = layout_.capacity[level + 1];
        parent_last = layout_.entries[2 + level] + p * parent_capacity + parent_capacity - 1u;
    }
    vec3 lo, hi;
    tile_box(tile, lo, hi);
    if (lo.x > hi.x) {  // no geometry: no receivers
        cut[lv.w + t] = 0u;
        return;
    }
    uint evaluate = 0u, traverse = 0u;
    // Depth-first from each root, without a stack (as hisr/gather.frag's
    // traverse_from), so the entries come in the same order every frame.
    for (uint r = 0u; r < roots; ++r) {
        ivec3 root = level + 1 < HISR_CUT_LEVELS ? cut_node(cut[parent_last - r])
                                                 : ivec3(int(r) % side, int(r) / side, start);
        ivec3 node = root;
        for (;;) {
            LightPatch lp = nodes[node_index(node)];
            if (lp.position_area.w > 0.0) {  // else: saw nothing
                // flux.a: the squared reach, -1 at the max depth (hisr_reach).
                float reach = lp.flux.a;
                vec3 p = lp.position_area.xyz;
                vec3 far = max(abs(p - lo), abs(p - hi));
                if (dot(far, far) <= reach) {
                    node = ivec3(2 * node.xy, node.z + 1);
                    continue;
                }
                vec3 near = max(max(lo - p, p - hi), vec3(0.0));
                bool disagree = dot(near, near) <= reach;
                // Evaluate entries (packed indices) from the front of the
                // range, traverse entries (cut_entry) from the back; they
                // must not meet.
                if (evaluate + traverse < capacity) {
                    uint at = disagree ? base + capacity - 1u - traverse : base + evaluate;
                    cut[at] = disagree ? cut_entry(node) : uint(node_index(node));
                }
                if (disagree) {
                    ++traverse;
                } else {
                    ++evaluate;
                }
            }
            if (!next_node(node, root.z)) break;
        }
    }
    cut[lv.w + t] = evaluate + traverse > capacity ? HISR_CUT_OVERFLOW : evaluate | (traverse << 16);
}
