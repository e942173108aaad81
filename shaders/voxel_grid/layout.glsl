// Where each level of the voxel occupancy grid lies in its buffer
// (docs/algorithm.md section 5, "Voxel visibility"): level 0, the finest
// cells, N^3 of them, then OR-levels k = 1.. of side N >> k, one bit per cell
// (a cell is occupied iff one of the finest cells under it is); cells x
// fastest, level after level. With sub-cells (GRID_SUB > 1) each finest cell
// is a 64-bit mask of its GRID_SUB^3 sub-cells (two words: sub-cell s =
// x + GRID_SUB (y + GRID_SUB z) in word s >> 5, bit s & 31), occupied iff its
// mask is not 0; without, one bit as at the other levels. Shared by the pass
// that builds the grid (voxel_grid/voxelize.comp, voxel_grid/levels.comp)
// and the march that reads it (voxel_grid/march.glsl), which reads it two words at
// a time: every level starts at an even word.
#ifndef VISIBILITY_LAYOUT_GLSL
#define VISIBILITY_LAYOUT_GLSL
#include "frame.glsl"

// Sub-cells per side of a finest cell: 1, 2 or 4 (`--visibility-subcells`,
// visibility::specialization, which every pipeline that
// includes this file is made with).
layout(constant_id = 21) const int GRID_SUB = 4;

// Words before level k: sum over i < k of level i's words, (N >> i)^3 / 32
// for a level of bits = (N^3 - (N >> k)^3) / 28 (a geometric sum of ratio
// 1/8; every level has at least 4^3 cells: whole, even counts of words); with
// sub-cells, level 0's masks take 2 N^3 words.
uint grid_level_offset(int k) {
    uint n = uint(run.grid_side);
    uint h = n >> 1u, m = n >> uint(k);
    if (GRID_SUB == 1) return (n * n * n - m * m * m) / 28u;
    return k == 0 ? 0u : 2u * n * n * n + (h * h * h - m * m * m) / 28u;
}

// Cell c's index within level k (side N >> k, a power of 2: shifts, not
// multiplies, which the march does at every step).
uint grid_cell_index(int k, ivec3 c) {
    int s = findMSB(run.grid_side) - k;
    return uint(c.x | (c.y << s) | (c.z << (2 * s)));
}

// The word of the grid's buffer that holds cell c of level k, and its bit
// there (a level of bits: k >= 1, or 0 without sub-cells).
uint grid_word(int k, ivec3 c) { return grid_level_offset(k) + (grid_cell_index(k, c) >> 5u); }
uint grid_bit(int k, ivec3 c) { return 1u << (grid_cell_index(k, c) & 31u); }

// With sub-cells, the first of the two words of finest cell c's mask.
uint grid_mask_word(ivec3 c) { return 2u * grid_cell_index(0, c); }

// Sub-cell q's (each component 0 .. GRID_SUB - 1) bit index in its cell's mask.
uint grid_sub_bit(ivec3 q) { return uint(q.x + GRID_SUB * (q.y + GRID_SUB * q.z)); }

#endif
