// HISR's quadtree addressing and subdivision test (docs/algorithm.md section
// 4), shared by the per-fragment traversal (multires/gather.frag) and the per-tile cut
// (hisr/cut.comp), which must decide exactly alike. Needs frame.glsl,
// light_types.glsl and shared.glsl.
#ifndef HISR_GLSL
#define HISR_GLSL

// Node (x, y) of depth z (2^z x 2^z patches) in the packed tree
// (hisr/tree_pack.comp): depth-major from the root, row-major inside.
int node_index(ivec3 node) { return ((1 << (2 * node.z)) - 1) / 3 + node.y * (1 << node.z) + node.x; }

// The depth of the node at packed index i: depth z holds indices
// (4^z - 1) / 3 .. (4^(z+1) - 1) / 3 - 1, so 4^z <= 3 i + 1 < 4^(z+1).
int node_depth(uint i) { return findMSB(3u * i + 1u) / 2; }

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
// Absolute tau (the talk): multires/gather.frag has the derivation; the per-level
// factor 4^k, k the node's levels above the finest RSM texel.
float hisr_reach(LightPatch lp, ivec3 node) {
    if (node.z >= run.hisr_max_depth || lp.position_area.w <= 0.0) return -1.0;
    float reach;
    if (run.hisr_tau_mode == HISR_TAU_RELATIVE) {
        reach = lp.position_area.w * (1.0 - run.hisr_tau) / (PI * run.hisr_tau);
    } else {
        int mip = run.rsm_top_level - node.z;
        reach = exp2(float(2 * mip)) * hisr_bound(lp.position_area.xyz, node, run.hisr_threshold);
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
