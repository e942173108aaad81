#version 460
// Pass `hisr-visibility` (HISR with --visibility voxels and shared tile
// visibility, docs/algorithm.md section 5, "Tile-shared visibility"): the
// entries of a tile's cut are the same for every receiver in it, so their
// visibility is marched once from each of the finest tile's four corner
// pixels instead of once per receiver: the three levels' evaluate entries,
// and the finest level's traverse entries toward their walk's root. The
// gather interpolates the four (traverse_cut_shared).
// One workgroup per finest tile, its 64 lanes striding over the entries the
// tile's cuts hold this frame (the three levels' evaluate entries, coarsest
// first, then the finest level's traverse entries): an invocation per slot
// of the capacities left most of them idle (some 57 ms of 65-80 on lavapipe
// at 256x256). Each entry's word goes to its slot, as the gather reads them.
// Each entry whose corners disagree by more than --hisr-shared-refine, or
// which no corner with geometry sees, also gets its march bit, so the
// gather's loops skip to the next entry of their kind by words of 32 slots
// (testing each entry's word there cost as much as the gather without the
// grid on lavapipe, most of it in the marched loop's scan).
// The four corners are the G-buffer pixels at the tile's
// corners (the far ones are the next tiles' first pixels, clamped to the
// image), so neighbouring tiles march from the same points.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "light_types.glsl"
#include "voxel_grid/march.glsl"
#include "hisr/hisr.glsl"
#include "hisr/tile_points.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

// --hisr-shared-refine (hisr/gather.frag's REFINE_SPREAD): the corners' spread
// past which every receiver marches an entry itself; 1: none does.
layout(constant_id = 31) const float REFINE_SPREAD = 1.0;

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;  // xyz world, w view depth (0: background)
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 1, binding = 2, std430) readonly buffer LightTree {
    uint node_count;
    uint pad0, pad1, pad2;
    LightPatch nodes[];  // the packed tree (hisr/tree_pack.comp)
};
layout(set = 1, binding = 3, std430) buffer HisrCut {
    HisrCutHeader header;
    uint cut[];  // per level counts, then per level entries, then the visibilities (shared.glsl)
};
#define GEO_LEVEL0_ONLY
#include "multires/geo_levels.glsl"

// The further point being chosen (hisr/tile_points.glsl): its key's minimum.
shared uint chosen;

void main() {
    uvec2 tile = gl_WorkGroupID.xy;
    uvec4 finest = header.tiles[0];
    if (tile.x >= finest.x || tile.y >= finest.y) return;
    uint t = tile.y * finest.x + tile.x;
    // A finer tile overflows where a coarser one does (hisr/cut.comp), so the
    // finest tile's count says whether the gather reads these at all.
    if (cut[finest.w + t] == HISR_CUT_OVERFLOW) return;
    // Per level (coarsest first) the tile's evaluate count and first slot;
    // the finest level's traverse entries after its evaluate entries.
    uint evaluate[HISR_CUT_LEVELS];
    uint at[HISR_CUT_LEVELS];
    uint total = 0u;
    for (int c = 0; c < HISR_CUT_LEVELS; ++c) {
        uvec2 tc = tile >> uint(c);
        at[c] = tc.y * header.tiles[c].x + tc.x;
        evaluate[c] = cut[header.tiles[c].w + at[c]] & 0xffffu;
        total += evaluate[c];
    }
    uint traverse = cut[finest.w + t] >> 16;
    total += traverse;
    int side = 1 << finest.z;
    ivec2 origin = ivec2(tile) * side;
    // This frame's march bits start clear (every lane, then the barrier,
    // before any sets one: the early returns above are the whole
    // workgroup's).
    uint bits = header.visibility.z + t * header.visibility.w;
    uint point_bits = header.points.z + t * header.visibility.w;
    for (uint w = gl_LocalInvocationIndex; w < header.visibility.w; w += 64u) {
        cut[bits + w] = 0u;
        if (header.points.y != 0u) cut[point_bits + w] = 0u;
    }
    memoryBarrierBuffer();
    barrier();
    vec4 corner[4];
    vec3 corner_normal[4];
    for (int k = 0; k < 4; ++k) {
        ivec2 px = min(origin + side * ivec2(k & 1, k >> 1), ivec2(run.output_size) - 1);
        corner[k] = level0_mean(px);
        corner_normal[k] = level0_normal(px).xyz;
    }
    // The further points: while some pixel of the tile is on none of the
    // corners' surfaces (tile_point_weight 0, where the gather's receiver
    // would march every entry itself) and weighs no chosen point 0.5 or
    // more, the uncovered pixel nearest the tile's centre (the lowest index
    // among equals), up to TILE_POINTS of them.
    vec4 point[TILE_POINTS];
    vec3 point_normal[TILE_POINTS];
    int points = 0;
    if (header.points.y != 0u) {
        ivec2 size = min(ivec2(side), ivec2(run.output_size) - origin);
        uint pixels = uint(size.x * size.y);
        for (int m = 0; m < TILE_POINTS; ++m) {
            if (gl_LocalInvocationIndex == 0u) chosen = TILE_POINT_NONE;
            barrier();
            for (uint q = gl_LocalInvocationIndex; q < pixels; q += 64u) {
                ivec2 d = ivec2(q % uint(size.x), q / uint(size.x));
                vec4 x = level0_mean(origin + d);
                if (x.w <= 0.0) continue;
                vec3 nx = level0_normal(origin + d).xyz;
                bool covered = false;
                for (int k = 0; k < 4; ++k) {
                    covered = covered || (corner[k].w > 0.0 && tile_point_weight(x.xyz, nx, corner[k].xyz, corner_normal[k]) > 0.0);
                }
                for (int k = 0; k < m; ++k) {
                    covered = covered || tile_point_weight(x.xyz, nx, point[k].xyz, point_normal[k]) >= 0.5;
                }
                // Squared distance from the centre in half pixels (clamped
                // past tiles of 128 pixels a side), then the index (a tile
                // is at most 256 pixels a side).
                ivec2 r = 2 * d + 1 - size;
                uint key = (min(uint(r.x * r.x + r.y * r.y), 0xffffu) << 16) | q;
                if (!covered) atomicMin(chosen, key);
            }
            barrier();
            uint pick = chosen;
            // Every lane has read it before lane 0 clears it again.
            barrier();
            if (pick == TILE_POINT_NONE) break;
            ivec2 px = origin + ivec2((pick & 0xffffu) % uint(size.x), (pick & 0xffffu) / uint(size.x));
            point[m] = level0_mean(px);
            point_normal[m] = level0_normal(px).xyz;
            if (gl_LocalInvocationIndex == 0u) cut[header.points.x + t * uint(TILE_POINTS) + uint(m)] = (uint(px.y) << 16) | uint(px.x);
            points = m + 1;
        }
        if (gl_LocalInvocationIndex == 0u && points < TILE_POINTS) {
            cut[header.points.x + t * uint(TILE_POINTS) + uint(points)] = TILE_POINT_NONE;
        }
    }
    for (uint j = gl_LocalInvocationIndex; j < total; j += 64u) {
        // Entry j's level c, index i there and slot (the capacities of the
        // coarser levels, then i).
        int c = HISR_CUT_LEVELS - 1;
        uint i = j;
        uint slot = 0u;
        while (c > 0 && i >= evaluate[c]) {
            i -= evaluate[c];
            slot += header.capacity[c];
            --c;
        }
        uint e;
        if (i < evaluate[0] || c > 0) {
            e = cut[header.entries[1 + c] + at[c] * header.capacity[c] + i];
        } else {
            // The finest level's traverse entries, from the back of its range.
            i = header.capacity[0] - 1u - (i - evaluate[0]);
            e = uint(node_index(cut_node(cut[header.entries[1] + t * header.capacity[0] + i])));
        }
        LightPatch lp = nodes[e];
        vec4 v = vec4(1.0);
        float lo = 1.0, hi = 0.0;
        for (int k = 0; k < 4; ++k) {
            // A corner without geometry is never used (the gather gives it no weight).
            if (corner[k].w > 0.0) {
                v[k] = voxel_visibility(corner[k].xyz, corner_normal[k], lp.position_area.xyz, lp.normal.xyz, lp.position_area.w);
                widen_spread(lo, hi, v[k]);
            }
        }
        slot += i;
        cut[header.visibility.x + t * header.visibility.y + slot] = packUnorm4x8(v);
        if (points > 0) {
            vec4 w = vec4(1.0);
            for (int k = 0; k < points; ++k) {
                w[k] = voxel_visibility(point[k].xyz, point_normal[k], lp.position_area.xyz, lp.normal.xyz, lp.position_area.w);
            }
            cut[header.points.y + t * header.visibility.y + slot] = packUnorm4x8(w);
            // The receivers that take the points march where the corners
            // and points together disagree (their own bits); where no
            // corner has geometry, the corners' spread is the points'.
            float plo = lo, phi = hi;
            for (int k = 0; k < points; ++k) widen_spread(plo, phi, w[k]);
            if (hi < lo) {
                lo = plo;
                hi = phi;
            }
            if (REFINE_SPREAD < 1.0 && phi - plo > REFINE_SPREAD) {
                atomicOr(cut[point_bits + (slot >> 5u)], 1u << (slot & 31u));
            }
        }
        // hi < lo: no corner (nor point) has geometry.
        if (REFINE_SPREAD < 1.0 && (hi < lo || hi - lo > REFINE_SPREAD)) {
            atomicOr(cut[bits + (slot >> 5u)], 1u << (slot & 31u));
        }
    }
}
