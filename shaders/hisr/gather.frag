#version 460
// HISR's gather (docs/algorithm.md section 4.3): every eye-space patch
// traverses the packed light tree itself (hisr/tree_pack.comp), from the
// roots, or with tiles (TILED, --hisr-tile-level K > 0) from its tile's
// shared cut (hisr/cut.comp). The frame of the pass, and add_patch, are
// multires/gather.glsl's.
#extension GL_GOOGLE_include_directive : require
#include "multires/gather.glsl"
#include "hisr/hisr.glsl"
#include "hisr/tile_points.glsl"

// Whether the traversal starts from the tiles' cuts (hisr/cut.comp).
layout(constant_id = 33) const bool TILED = false;
// With tiles and --visibility voxels: the tiles' shared visibility
// (hisr/visibility.comp, --hisr-shared-visibility).
layout(constant_id = 30) const bool SHARED_VISIBILITY = false;
// --hisr-shared-refine: the corners' spread past which a receiver marches
// a patch itself (next_entry; hisr/visibility.comp sets the bits); 1 never does.
layout(constant_id = 31) const float REFINE_SPREAD = 1.0;

layout(set = 1, binding = GATHER_SOURCE_BINDING, std430) readonly buffer LightTree {
    uint node_count;
    uint pad0, pad1, pad2;
    LightPatch nodes[];  // the packed tree, root first (hisr/tree_pack.comp)
};
// The tiles' cuts (hisr/cut.comp; read only when TILED).
layout(set = 1, binding = GATHER_SOURCE_BINDING + 1, std430) readonly buffer HisrCut {
    HisrCutHeader cut_header;
    uint cut[];  // per level counts, then per level entries (hisr/hisr.glsl)
};

// Hierarchical ISR (docs/algorithm.md section 4.3): subdivide patch j while
// its form factor seen from this receiver exceeds tau (relative tau, the
// default: hisr_reach in hisr/hisr.glsl), or, with --hisr-tau-mode absolute, while
// its contribution could exceed tau times the light's peak intensity, derived
// here.
//
// The absolute bound. With rho <= 1 and both cosines <= 1, Phi_j = rho_j I dw_j and
// A_j = dw_j |V_j|^2 / cos_j >= dw_j |V_j|^2 (section 2) give
//   C_{j->i} <= I dw_j / (pi |V_ij|^2 + dw_j |V_j|^2).
// The talk takes one texel's solid angle as dw = 2 pi / (3 R^2) and scales by
// |V_j|^2, which makes the bound independent of the light's distance and
// gives its form: C <= 2 I |V_j|^2 / (3 R^2 |V_ij|^2 + 2 |V_j|^2). Requiring
// it to exceed tau:
//   subdivide j  iff  |V_ij|^2 <= T |V_j|^2,  T = 2 (I - tau) / (3 tau R^2),
// constant per run (HISR_THRESHOLD; `--tau` is tau / I, so the host
// computes T = 2 (1 - tau) / (3 tau R^2), in the one place it is evaluated).
// The per-level factor: a patch k levels above the finest stands
// for 4^k texels, i.e. one texel of an (R / 2^k)^2 RSM, so R^2 becomes
// R^2 / 4^k and its threshold 4^k T. For cube faces and orthographic RSMs
// the right-hand side differs: hisr_bound in light_types.glsl derives it.
//
// Invalid patches (spanning a discontinuity) are held to a tighter test: the
// bound above drops both cosines, so it holds for them too, but their mean
// position and normal can misplace their whole contribution, where a valid
// patch's misplace only a small part of it. An invalid patch is split while
// its bound could exceed tau * HISR_INVALID_TAU_SCALE, i.e. against the
// threshold T / HISR_INVALID_TAU_SCALE (for small tau). Splitting them always
// costs about 520 evaluations per fragment in the Cornell box whatever tau
// is; docs/algorithm.md section 4.3 has the measurements behind the scale.
//
// Depth-first without a stack (next_node in hisr/hisr.glsl): the tree is implicit
// (a node's children are (2x + i, 2y + j) one depth down), so the next node
// follows from its coordinates. No per-fragment array: on GPUs a stack spills to memory, and CPU
// drivers turn each indexed access into selects over all its entries.
// The nodes come from the packed tree (hisr/tree_pack.comp; node_index in
// hisr/hisr.glsl).
// march, v: as add_patch's, for every patch of the walk.
void traverse_from(vec3 xi, vec3 ni, ivec3 root, bool march, float v) {
    ivec3 node = root;  // xy: patch coordinates; z: depth (2^z x 2^z patches at that depth)
    for (;;) {
        LightPatch lp = nodes[node_index(node)];
        // Empty nodes (saw nothing) are skipped before the split test, although
        // their reach (-1) never splits: with the test first, lavapipe shaded the
        // fragments of silhouette columns as if no node split (the tile-cut test
        // catches it; the cause was not found).
        if (lp.position_area.w > 0.0) {
            vec3 vij = lp.position_area.xyz - xi;
            // flux.a: the squared reach, -1 at the max depth (hisr_reach,
            // stored by light-tree-pack).
            if (dot(vij, vij) <= lp.flux.a) {
                node = ivec3(2 * node.xy, node.z + 1);
                continue;
            }
            add_patch(xi, ni, lp.position_area, lp.normal, lp.flux.rgb, patch_level(run.rsm_top_level - node.z, lp.normal.w), march, v);
        }
        if (!next_node(node, root.z)) return;
    }
}

// From the 2^s x 2^s patches of the start depth.
void traverse(vec3 xi, vec3 ni) {
    int start = HISR_START_DEPTH;
    int side = 1 << start;
    for (int s = 0; s < side * side; ++s) traverse_from(xi, ni, ivec3(s % side, s / side, start), true, 1.0);
}

// From the cuts of the tiles holding texel p of this level (hisr/cut.comp):
// the finest cut level c0 whose tiles are at least this level's texels, and
// every coarser one. Their "evaluate" entries together with c0's "traverse"
// entries are c0's tile's whole cut: the evaluate entries are the same for
// every receiver of a tile and are summed in plain list loops; only the
// traverse entries are walked per fragment (in a loop of their own: lavapipe
// runs both sides of a branch under a lane mask, so one loop with a branch
// per entry cost the plain entries as much as the walks). Levels coarser
// than every tile, and tiles whose cut overflowed, traverse from the roots.
uint tile_at(ivec2 p, int c) {
    uvec4 lv = cut_header.tiles[c];
    uvec2 tile = uvec2(p >> (int(lv.z) - level));
    return tile.y * lv.x + tile.x;
}

// HISR's tile-shared visibility (hisr/visibility.comp; docs/algorithm.md
// section 5, "Tile-shared visibility"): the cut entries' visibility from the
// finest tile's four corner pixels, interpolated bilinearly at the receiver
// over the corners on its own surface (tile_point_weight). A receiver on
// none of them takes the tile's further points on its surface
// (hisr/visibility.comp chose them where the corners leave pixels
// uncovered), and on none of those either (at creases and silhouettes)
// marches itself (sv.own; with --hisr-shared-refine 1 there are no further
// points and it takes the plain bilinear mean of the corners that have
// geometry).
struct SharedVisibility {
    vec4 weights;  // per corner, or per further point with `points`; normalised
    bool points;   // whether the weights are the further points'
    bool own;      // whether the receiver marches every entry itself
    uint base;     // the finest tile's first visibility word
    uint bits;     // the finest tile's first word of march bits
};

SharedVisibility shared_visibility(vec3 xi, vec3 ni, ivec2 p, uint t0) {
    SharedVisibility sv;
    sv.weights = vec4(0.0);
    sv.points = false;
    sv.base = cut_header.visibility.x + t0 * cut_header.visibility.y;
    sv.bits = cut_header.visibility.z + t0 * cut_header.visibility.w;
    uvec4 finest = cut_header.tiles[0];
    int side = 1 << finest.z;
    ivec2 origin = ivec2(t0 % finest.x, t0 / finest.x) * side;
    // The receiver's centre in pixels (a level's texel covers 2^level of them).
    vec2 centre = (vec2(p) + 0.5) * float(1 << level);
    vec2 uv = clamp((centre - (vec2(origin) + 0.5)) / float(side), 0.0, 1.0);
    vec4 bilinear = vec4((1.0 - uv.x) * (1.0 - uv.y), uv.x * (1.0 - uv.y), (1.0 - uv.x) * uv.y, uv.x * uv.y);
    vec3 n = normalize(ni);
    vec4 geometry = vec4(0.0);
    for (int k = 0; k < 4; ++k) {
        ivec2 px = min(origin + side * ivec2(k & 1, k >> 1), ivec2(run.output_size) - 1);
        vec4 x = level0_mean(px);
        if (x.w <= 0.0) continue;
        geometry[k] = bilinear[k] + 1e-3;
        // geometry[k] holds a little weight at the far corners too, so a
        // receiver at a corner that is not on its surface still finds the
        // others.
        sv.weights[k] = geometry[k] * tile_point_weight(xi, n, x.xyz, level0_normal(px).xyz);
    }
    float w = sv.weights.x + sv.weights.y + sv.weights.z + sv.weights.w;
    if (w <= 0.0 && cut_header.points.y != 0u) {
        // The further points on the receiver's surface, by their weights.
        for (int k = 0; k < TILE_POINTS; ++k) {
            uint at = cut[cut_header.points.x + t0 * uint(TILE_POINTS) + uint(k)];
            if (at == TILE_POINT_NONE) break;
            ivec2 px = ivec2(at & 0xffffu, at >> 16);
            sv.weights[k] = tile_point_weight(xi, n, level0_mean(px).xyz, level0_normal(px).xyz);
        }
        w = sv.weights.x + sv.weights.y + sv.weights.z + sv.weights.w;
        sv.points = w > 0.0;
        // Their march bits, from the corners' and the points' spread.
        if (sv.points) sv.bits = cut_header.points.z + t0 * cut_header.visibility.w;
    }
    // A receiver on none of the points' surfaces marches itself.
    sv.own = REFINE_SPREAD < 1.0 && w <= 0.0;
    if (w <= 0.0) {
        sv.weights = geometry;
        w = max(geometry.x + geometry.y + geometry.z + geometry.w, 1e-30);
    }
    sv.weights /= w;
    return sv;
}

// The interpolated visibility of the entry whose corners' word is at `word`
// (the further points' word is as far on as their region is from the
// corners').
float shared_value(SharedVisibility sv, uint word) {
    if (sv.points) word += cut_header.points.y - cut_header.visibility.x;
    return dot(sv.weights, unpackUnorm4x8(cut[word]));
}

// The first entry from i below n that the receiver marches itself (`march`)
// or interpolates; entry k's word is at first + k, or first - k with `back`.
// It marches every entry where it is on none of the corners' surfaces
// (sv.own), and otherwise the entries whose march bit hisr/visibility.comp
// set: the corners with geometry differ by more than --hisr-shared-refine,
// or none has geometry. Only sv.own differs between the fragments of a
// tile. The entries are taken in two loops, the interpolated ones and the
// marched ones, each skipping to its next entry here a word of 32 bits at a
// time: lavapipe runs a branch's body under a lane mask even when no lane
// takes it, so a march behind a branch in the entries' loop cost every
// entry its set-up (the gather 1.6x with no patch marched), and testing
// every entry's word in the skip cost the marched loop as much again.
uint next_entry(SharedVisibility sv, uint first, bool back, uint i, uint n, bool march) {
    if (REFINE_SPREAD >= 1.0) return march ? n : i;
    if (sv.own) return march ? i : n;
    uint flip = march ? 0u : 0xffffffffu;
    while (i < n) {
        uint s = (back ? first - i : first + i) - sv.base;  // its slot in the tile
        uint b = s & 31u;
        // The bits of the entries from i on in this word.
        uint bits = (cut[sv.bits + (s >> 5u)] ^ flip) & (back ? 0xffffffffu >> (31u - b) : 0xffffffffu << b);
        if (bits != 0u) return min(i + (back ? b - uint(findMSB(bits)) : uint(findLSB(bits)) - b), n);
        i += back ? b + 1u : 32u - b;
    }
    return n;
}

// With shared visibility, the receivers of the finest tiles' levels: every
// evaluate entry and every walk of a traverse entry takes its visibility
// from the corners (hisr/visibility.comp) or, where next_entry() says, from
// the receiver's own march (a walk's of each of its patches: marching only
// toward its root left the box with blocks at 128x128 0.026 from the
// per-receiver march, against 0.018).
void traverse_cut_shared(vec3 xi, vec3 ni, ivec2 p, uint t0, uint counts) {
    SharedVisibility sv = shared_visibility(xi, ni, p, t0);
    uint slot = sv.base;  // the visibility words follow the loops' order
    for (int c = HISR_CUT_LEVELS - 1; c >= 0; --c) {
        uint t = tile_at(p, c);
        uint n = (c == 0 ? counts : cut[cut_header.tiles[c].w + t]) & 0xffffu;
        uint base = cut_header.entries[1 + c] + t * cut_header.capacity[c];
        for (uint i = next_entry(sv, slot, false, 0u, n, false); i < n; i = next_entry(sv, slot, false, i + 1u, n, false)) {
            uint index = cut[base + i];  // a packed index
            LightPatch lp = nodes[index];
            float v = shared_value(sv, slot + i);
            add_patch(xi, ni, lp.position_area, lp.normal, lp.flux.rgb,
                      patch_level(run.rsm_top_level - node_depth(index), lp.normal.w), false, v);
        }
        if (REFINE_SPREAD < 1.0) {
            for (uint i = next_entry(sv, slot, false, 0u, n, true); i < n; i = next_entry(sv, slot, false, i + 1u, n, true)) {
                uint index = cut[base + i];
                LightPatch lp = nodes[index];
                add_patch(xi, ni, lp.position_area, lp.normal, lp.flux.rgb,
                          patch_level(run.rsm_top_level - node_depth(index), lp.normal.w), true, 1.0);
            }
        }
        slot += cut_header.capacity[c];
    }
    // slot is now past level 0's range: its traverse entries are at its
    // back, entry i's word at slot - 1 - i.
    uint capacity = cut_header.capacity[0];
    uint last = cut_header.entries[1] + t0 * capacity + capacity - 1u;
    uint walks = counts >> 16;
    for (uint i = next_entry(sv, slot - 1u, true, 0u, walks, false); i < walks; i = next_entry(sv, slot - 1u, true, i + 1u, walks, false)) {
        float v = shared_value(sv, slot - 1u - i);
        traverse_from(xi, ni, cut_node(cut[last - i]), false, v);
    }
    if (REFINE_SPREAD < 1.0) {
        for (uint i = next_entry(sv, slot - 1u, true, 0u, walks, true); i < walks; i = next_entry(sv, slot - 1u, true, i + 1u, walks, true)) {
            traverse_from(xi, ni, cut_node(cut[last - i]), true, 1.0);
        }
    }
}

void traverse_cut(vec3 xi, vec3 ni, ivec2 p) {
    int c0 = max(level - int(cut_header.tiles[0].z), 0);
    if (c0 >= HISR_CUT_LEVELS) {
        traverse(xi, ni);
        return;
    }
    uint t0 = tile_at(p, c0);
    uint counts = cut[cut_header.tiles[c0].w + t0];
    if (counts == HISR_CUT_OVERFLOW) {
        traverse(xi, ni);
        return;
    }
    if (SHARED_VISIBILITY && c0 == 0) {
        traverse_cut_shared(xi, ni, p, t0, counts);
        return;
    }
    for (int c = HISR_CUT_LEVELS - 1; c >= c0; --c) {
        uint t = tile_at(p, c);
        uint n = (c == c0 ? counts : cut[cut_header.tiles[c].w + t]) & 0xffffu;
        uint base = cut_header.entries[1 + c] + t * cut_header.capacity[c];
        for (uint i = 0u; i < n; ++i) {
            uint index = cut[base + i];  // a packed index
            LightPatch lp = nodes[index];
            add_patch(xi, ni, lp.position_area, lp.normal, lp.flux.rgb,
                      patch_level(run.rsm_top_level - node_depth(index), lp.normal.w), true, 1.0);
        }
    }
    uint capacity = cut_header.capacity[c0];
    uint last = cut_header.entries[1 + c0] + t0 * capacity + capacity - 1u;
    for (uint i = 0u; i < counts >> 16; ++i) traverse_from(xi, ni, cut_node(cut[last - i]), true, 1.0);
}

void gather_patches(vec3 xi, vec3 ni, ivec2 p) {
    if (TILED) {
        traverse_cut(xi, ni, p);
    } else {
        traverse(xi, ni);
    }
}
