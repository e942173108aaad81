// HISR's parameters, its quadtree addressing and subdivision test
// (docs/algorithm.md section 4.3), and the layout of its tile cuts (4.4),
// shared by the tree's packing (hisr/tree_pack.comp), the per-tile cut
// (hisr/cut.comp), the tiles' visibility (hisr/visibility.comp) and the
// per-fragment traversal (hisr/gather.frag), which must decide exactly
// alike. Needs frame.glsl and light_types.glsl.
#ifndef HISR_GLSL
#define HISR_GLSL

// The run's parameters (methods::hisr::constants sets them from --tau,
// --hisr-tau-mode, --start-level and --max-depth).
layout(constant_id = 34) const float HISR_TAU = 0.2;
// Absolute tau (the talk's bound); relative by default.
layout(constant_id = 35) const bool HISR_TAU_ABSOLUTE = false;
// The absolute tau's T at the finest level, computed once on the host
// (methods::hisr::subdivision_threshold; hisr/gather.frag derives the test).
layout(constant_id = 36) const float HISR_THRESHOLD = 0.0;
// The traversal starts from 2^s x 2^s patches and subdivides down to 2^d x 2^d.
layout(constant_id = 37) const int HISR_START_DEPTH = 2;
layout(constant_id = 38) const int HISR_MAX_DEPTH = 8;

// HISR splits an invalid patch while its bound could exceed tau times this
// (hisr/gather.frag, docs/algorithm.md section 4.3).
const float HISR_INVALID_TAU_SCALE = 0.01;

// HISR's per-tile cuts (docs/algorithm.md section 4.4) come in
// HISR_CUT_LEVELS chained levels: level c has tiles of 2^(K + c) pixels a
// side; the coarsest is cut from the start depth, each finer one from its
// parent tile's "traverse" entries. Layout of the buffer (hisr/cut.comp
// writes it, hisr/gather.frag reads it): this header, then per level a count per
// tile, then per level `capacity` entries per tile (hisr/hisr.glsl: packed indices
// for evaluate entries, cut_entry for traverse entries):
// a tile's "evaluate" entries from the front of its range, its "traverse"
// entries from the back. A count holds the evaluate entries in bits 0-15 and
// the traverse entries in bits 16-31, or is HISR_CUT_OVERFLOW. Offsets count
// uints after the header. With the voxel grid and shared tile visibility,
// then per finest tile one word per slot of the three levels (coarsest
// level first; evaluate entries, and the finest level's traverse entries):
// the entry's visibility from the tile's four corner pixels, packUnorm4x8 (hisr/visibility.comp writes it, hisr/gather.frag
// interpolates it); then per finest tile a bit per slot, set where every
// receiver marches the entry itself (the corners disagree or none has
// geometry: hisr/visibility.comp), so the gather finds the entries of each
// kind a word of 32 slots at a time; then (with refinement) the tile's
// further points, their visibilities and march bits (HisrCutHeader.points).
const int HISR_CUT_LEVELS = 3;
struct HisrCutHeader {
    uvec4 tiles[HISR_CUT_LEVELS];  // per level: x, y: tiles per row and column; z: tile
                                   // level K + c; w: offset of its counts
    uvec4 entries;                 // y, z, w: offset of levels 0, 1, 2's entries; x: of the
                                   // finest tiles' boxes (8 floats each, hisr/cut.comp)
    uvec4 capacity;                // x, y, z: entries per tile of levels 0, 1, 2
    uvec4 visibility;              // x: offset of the entries' corner visibilities
                                   // (hisr/visibility.comp), 0 without them; y: their slots
                                   // per finest tile (the capacities' sum); z: offset of
                                   // the march bits; w: their words per finest tile
    uvec4 points;                  // x: offset of the tile points' pixels (4 words per
                                   // finest tile, (y << 16) | x, ~0u past the last);
                                   // y: of their visibilities, as the corners' (0 without);
                                   // z: of their receivers' march bits, as the corners'
                                   // (hisr/tile_points.glsl)
};

// A tile whose cut did not fit: its fragments traverse from the roots.
const uint HISR_CUT_OVERFLOW = 4294967295u;

// Node (x, y) of depth z (2^z x 2^z patches) in the packed tree
// (hisr/tree_pack.comp): depth-major from the root, row-major inside.
int node_index(ivec3 node) { return ((1 << (2 * node.z)) - 1) / 3 + node.y * (1 << node.z) + node.x; }

// The depth of the node at packed index i: depth z holds indices
// (4^z - 1) / 3 .. (4^(z+1) - 1) / 3 - 1, so 4^z <= 3 i + 1 < 4^(z+1).
int node_depth(uint i) { return findMSB(3u * i + 1u) / 2; }

// The absolute tau (hisr/gather.frag, docs/algorithm.md sections 2.4 and 4.3): subdivide patch j
// (mean position pj, node xy at depth d: 2^d x 2^d patches across the RSM)
// iff |V_ij|^2 <= 4^k * hisr_bound(...), k its levels above the finest.
// t_finest is T of hisr/gather.frag's derivation (HISR_THRESHOLD), which is
// dw_talk (1 - tau) / (pi tau) with the talk's texel solid angle
// dw_talk = 2 pi / (3 R^2).
//
// Spot (the talk): C_ij <= I dw / (pi |V_ij|^2 + dw |V_j|^2) > tau I / |V_j|^2
//   iff |V_ij|^2 < dw (1 - tau) / (pi tau) |V_j|^2 = T |V_j|^2 with dw = dw_talk.
// Cube face: the same inequality holds with dw the largest texel solid angle
//   in the patch. On a 90 degree face dw = (2/R)^2 cos^3 alpha, largest at the
//   patch's point nearest the face centre (alpha smallest); so the bound is
//   T |V_j|^2 dw_max / dw_talk = T |V_j|^2 * 6 cos^3 alpha_min / pi: exact for
//   every texel rather than one average solid angle (texels shrink ~5x toward
//   the face's corners, where this splits less).
// Orthographic: Phi_j <= E m a and A_j >= m a for the patch's m <= 4^k
//   non-empty texels of area a = (2h/R)^2 (no light distance), and
//   Phi / (pi d^2 + A) grows with m: C_ij <= E 4^k a / (pi |V_ij|^2 + 4^k a),
//   above tau E iff |V_ij|^2 < 4^k a (1 - tau) / (pi tau) = 4^k T a / dw_talk
//   = 4^k T 6 h^2 / pi.
float hisr_bound(vec3 pj, ivec3 node, float t_finest) {
    if (light_is_directional()) {
        float h = u.rsm_half_extent;
        return t_finest * 6.0 * h * h / PI;
    }
    vec3 vj = pj - u.light_position;
    float bound = t_finest * dot(vj, vj);
    if (u.light_kind == LIGHT_POINT) {
        // The patch's square on the face's image plane [-1, 1]^2, and its
        // point nearest the centre.
        float side = float(1 << node.z);
        vec2 lo = vec2(node.xy) / side * 2.0 - 1.0;
        vec2 hi = lo + 2.0 / side;
        vec2 nearest = clamp(vec2(0.0), lo, hi);
        float cos_alpha = inversesqrt(1.0 + dot(nearest, nearest));
        bound *= 6.0 * cos_alpha * cos_alpha * cos_alpha / PI;
    }
    return bound;
}


// The node's squared reach: patch j splits for receiver i iff
// |V_ij|^2 <= reach. Invalid patches have the reach over HISR_INVALID_TAU_SCALE.
// Nodes at the max depth, and empty ones, never split: -1. light-tree-pack
// stores it in the packed node's flux.a, so the traversal and the tile cut
// test a node with one comparison and decide exactly alike.
//
// Relative tau (docs/algorithm.md section 4.3): split while the patch's solid
// angle seen from the receiver, as the disc form factor A_j / (pi |V_ij|^2 +
// A_j) of section 2.6, exceeds tau:
//   A_j / (pi |V_ij|^2 + A_j) > tau  iff  |V_ij|^2 < A_j (1 - tau) / (pi tau).
// The patch's own summed area A_j: no per-level factor and no light type.
// Absolute tau (the talk): hisr/gather.frag has the derivation; the per-level
// factor 4^k, k the node's levels above the finest RSM texel.
float hisr_reach(LightPatch lp, ivec3 node) {
    if (node.z >= HISR_MAX_DEPTH || lp.position_area.w <= 0.0) return -1.0;
    float reach;
    if (!HISR_TAU_ABSOLUTE) {
        reach = lp.position_area.w * (1.0 - HISR_TAU) / (PI * HISR_TAU);
    } else {
        int mip = run.rsm_top_level - node.z;
        reach = exp2(float(2 * mip)) * hisr_bound(lp.position_area.xyz, node, HISR_THRESHOLD);
    }
    // Both forms hold invalid patches to the reach of s tau for small tau,
    // and let them stop splitting as tau -> 1 (the cheap end).
    if (lp.normal.w == PATCH_INVALID) reach /= HISR_INVALID_TAU_SCALE;
    return reach;
}

// Depth-first order without a stack: the tree is implicit, so after a node
// that is not split comes its next sibling (children in the order (0,0),
// (1,0), (0,1), (1,1)), or that of its nearest ancestor that has one. Moves
// `node` there; false when the subtree of the root at depth root_depth is done.
// The ancestors to climb are the last children in a row: as many levels as
// x & y has trailing ones (no loop, so no divergent inner loop per lane).
bool next_node(inout ivec3 node, int root_depth) {
    int up = min(findLSB(~(node.x & node.y)), node.z - root_depth);
    node = ivec3(node.xy >> up, node.z - up);
    if (node.z == root_depth) return false;
    node.xy += (node.x & 1) == 0 ? ivec2(1, 0) : ivec2(-1, 1);
    return true;
}

// A traverse entry of a tile's cut (HisrCutHeader): x in bits 0-11, y in
// 12-23, depth in 24-27 (the tree is at most 12 deep). Evaluate entries are
// the node's packed index (node_index), read without decoding.
uint cut_entry(ivec3 node) { return uint(node.x) | (uint(node.y) << 12) | (uint(node.z) << 24); }

ivec3 cut_node(uint entry) { return ivec3(entry & 0xfffu, (entry >> 12) & 0xfffu, (entry >> 24) & 0xfu); }

#endif
