#version 460
// Pass visibility-grid, its last dispatches (docs/algorithm.md section 5,
// "Voxel visibility"): OR-level k + 1 of the occupancy grid from level k,
// one dispatch per level (finest first, a barrier between), one invocation
// per 32-bit word of level k + 1, which it writes whole: a cell of level
// k + 1 is occupied iff one of its 8 children at level k is. Run after
// voxel_grid/voxelize.comp has set the finest level, so every level is exactly
// the OR of the finest cells under it, which the march (voxel_grid/march.glsl)
// takes for granted when it skips an empty coarse cell whole.
#extension GL_GOOGLE_include_directive : require
#include "voxel_grid/layout.glsl"
layout(local_size_x = 64) in;

layout(set = 0, binding = 3, std430) buffer GridOccupancy { uint visibility_bits[]; };
layout(push_constant) uniform Push { GridLevelPush push; };

bool occupied(int k, ivec3 c) {
    if (k == 0 && GRID_SUB > 1) {
        uint w = grid_mask_word(c);
        return (visibility_bits[w] | visibility_bits[w + 1u]) != 0u;
    }
    return (visibility_bits[grid_word(k, c)] & grid_bit(k, c)) != 0u;
}

// The bits 0, 2, ..., 30 of x, packed into bits 0..15.
uint even_bits(uint x) {
    x &= 0x55555555u;
    x = (x | (x >> 1u)) & 0x33333333u;
    x = (x | (x >> 2u)) & 0x0f0f0f0fu;
    x = (x | (x >> 4u)) & 0x00ff00ffu;
    return (x | (x >> 8u)) & 0x0000ffffu;
}

void main() {
    int k = push.level;  // the level read; k + 1 is written
    int n = run.grid_side >> (k + 1);
    uint word = gl_GlobalInvocationID.x;
    uint cells = uint(n * n * n);
    if (word >= cells / 32u) return;
    uint first = word * 32u;
    uint bits = 0u;
    if (n >= 32 && (k > 0 || GRID_SUB == 1)) {
        // The word is 32 cells of one row; their children are 64 cells of
        // each of four rows of level k, two whole words each.
        ivec3 c = ivec3(int(first % uint(n)), int((first / uint(n)) % uint(n)), int(first / uint(n * n)));
        uint lo = 0u, hi = 0u;
        for (int r = 0; r < 4; ++r) {
            uint at = grid_word(k, ivec3(2 * c.x, 2 * c.y + (r & 1), 2 * c.z + (r >> 1)));
            lo |= visibility_bits[at];
            hi |= visibility_bits[at + 1u];
        }
        // Neighbouring children along x are neighbouring bits.
        bits = even_bits(lo | (lo >> 1u)) | (even_bits(hi | (hi >> 1u)) << 16u);
    } else {
        // Level 1 from level 0's sub-cell masks, and coarse levels (up to
        // 16^3 cells), where a word holds several rows.
        for (uint b = 0u; b < 32u; ++b) {
            uint i = first + b;
            ivec3 c = ivec3(int(i % uint(n)), int((i / uint(n)) % uint(n)), int(i / uint(n * n)));
            bool any = false;
            for (int j = 0; j < 8; ++j) {
                any = any || occupied(k, 2 * c + ivec3(j & 1, (j >> 1) & 1, j >> 2));
            }
            if (any) bits |= 1u << b;
        }
    }
    visibility_bits[grid_level_offset(k + 1) + word] = bits;
}
