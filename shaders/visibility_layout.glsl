// Where each level of the voxel occupancy grid lies in its buffer
// (docs/algorithm.md section 5, "Voxel visibility"): N^3 finest cells, then
// OR-levels k = 1.. of side N >> k, one bit per cell, x fastest, level after
// level. Shared by the pass that builds the grid (visibility_grid.comp,
// visibility_grid_levels.comp) and the march that reads it (visibility.glsl).
#ifndef VISIBILITY_LAYOUT_GLSL
#define VISIBILITY_LAYOUT_GLSL
#include "frame.glsl"

// Words before level k: sum over i < k of (N >> i)^3 / 32 = (N^3 - (N >> k)^3) / 28
// (a geometric sum of ratio 1/8; every level has at least 4^3 cells, so whole words).
uint grid_level_offset(int k) {
    uint n = uint(run.visibility_side);
    uint m = n >> uint(k);
    return (n * n * n - m * m * m) / 28u;
}

// Cell c's index within level k (side N >> k, a power of 2: shifts, not
// multiplies, which the march does at every step).
uint grid_cell_index(int k, ivec3 c) {
    int s = findMSB(run.visibility_side) - k;
    return uint(c.x | (c.y << s) | (c.z << (2 * s)));
}

// The word of the grid's buffer that holds cell c of level k, and its bit there.
uint grid_word(int k, ivec3 c) { return grid_level_offset(k) + (grid_cell_index(k, c) >> 5u); }
uint grid_bit(int k, ivec3 c) { return 1u << (grid_cell_index(k, c) & 31u); }

#endif
