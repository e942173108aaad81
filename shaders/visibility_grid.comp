#version 460
// Pass visibility-grid, its first dispatches (docs/algorithm.md section 5,
// "Voxel visibility"): the finest level of the occupancy grid of this
// frame's posed scene, one invocation per triangle of one instance (placed
// by this frame's InstanceTransform) and tile of columns. Every finest cell
// the triangle touches gets its bit set with atomicOr, so the result does
// not depend on the order triangles run in. The coarser levels are ORs of
// this one, made after it by visibility_grid_levels.comp (voxelizing every
// level here took about 70% of the pass on the 277k triangles of the
// conference room).
//
// The test is the separating-axis test of a triangle and a box (Akenine-Moller
// 2001), made conservative by a small margin: the box's face normals come
// from visiting only the cells of the triangle's bounding box, the
// triangle's normal from visiting, in each column along the dominant axis of
// the normal, only the cells the plane crosses over that column; the nine
// axes edge x box-axis are tested per cell.
//
// Lavapipe ends a shader invocation's loops after 65,535 iterations
// together, so a triangle's columns are split into tiles of VISIBILITY_TILE
// x VISIBILITY_TILE (at most 3 cells per column, since the columns run along
// the normal's dominant axis: about 4,200 iterations a tile), and the
// dispatch's y invocations of a triangle take every y-th of its own tiles:
// visibility_grid.rs makes y large enough that none takes more than 8. (One
// invocation per tile of the whole grid instead, most of them returning at
// once, took the pass on the conference room from 37 ms to 382 with 4
// sub-cells.)
#extension GL_GOOGLE_include_directive : require
#include "visibility_layout.glsl"
layout(local_size_x = 64) in;

// Cleared before the dispatch (visibility_grid.rs).
layout(set = 0, binding = 3, std430) buffer VisibilityGrid { uint visibility_bits[]; };
layout(set = 1, binding = 0, std430) readonly buffer Vertices { float vertex_data[]; };  // GpuVertex: 8 floats
layout(set = 1, binding = 1, std430) readonly buffer Indices { uint index_data[]; };
layout(push_constant) uniform Push { VisibilityGridPush draw; };

// In cells: covers float error in the corners and faces the tests compare.
const float MARGIN = 1e-3;

// Columns per tile side (visibility_grid.rs: TILE).
const int VISIBILITY_TILE = 32;

vec3 vertex_position(uint index) {
    uint v = uint(int(index) + draw.vertex_offset) * 8u;
    return vec3(vertex_data[v], vertex_data[v + 1u], vertex_data[v + 2u]);
}

// Whether axis separates the triangle (vertices relative to the box centre)
// from the box of half side h.
bool separates(vec3 axis, vec3 v0, vec3 v1, vec3 v2, float h) {
    float p0 = dot(axis, v0), p1 = dot(axis, v1), p2 = dot(axis, v2);
    float r = h * (abs(axis.x) + abs(axis.y) + abs(axis.z));
    return min(p0, min(p1, p2)) > r || max(p0, max(p1, p2)) < -r;
}

// The nine axes e x (x, y, z) of one edge e.
bool edge_separates(vec3 e, vec3 v0, vec3 v1, vec3 v2, float h) {
    return separates(vec3(0.0, -e.z, e.y), v0, v1, v2, h)
        || separates(vec3(e.z, 0.0, -e.x), v0, v1, v2, h)
        || separates(vec3(-e.y, e.x, 0.0), v0, v1, v2, h);
}

bool touches(ivec3 cell, vec3 a, vec3 b, vec3 c) {
    vec3 centre = vec3(cell) + 0.5;
    vec3 v0 = a - centre, v1 = b - centre, v2 = c - centre;
    float h = 0.5 + MARGIN;
    return !(edge_separates(b - a, v0, v1, v2, h) || edge_separates(c - b, v0, v1, v2, h)
             || edge_separates(a - c, v0, v1, v2, h));
}

// Sets sub-cell s's bit (in sub-cells of the whole grid) in its finest
// cell's mask, or without sub-cells the finest cell s's bit.
void set_sub_cell(ivec3 s) {
    if (GRID_SUB == 1) {
        atomicOr(visibility_bits[grid_word(0, s)], grid_bit(0, s));
        return;
    }
    uint b = grid_sub_bit(s & (GRID_SUB - 1));
    atomicOr(visibility_bits[grid_mask_word(s / GRID_SUB) + (b >> 5u)], 1u << (b & 31u));
}

// Marks the sub-cells the triangle a, b, c (in sub-cells) touches.
void mark(vec3 a, vec3 b, vec3 c) {
    int n = run.visibility_side * GRID_SUB;
    vec3 lo = min(a, min(b, c)) - MARGIN, hi = max(a, max(b, c)) + MARGIN;
    if (any(lessThan(hi, vec3(0.0))) || any(greaterThanEqual(lo, vec3(float(n))))) return;
    ivec3 clo = clamp(ivec3(floor(lo)), ivec3(0), ivec3(n - 1));
    ivec3 chi = clamp(ivec3(floor(hi)), ivec3(0), ivec3(n - 1));
    vec3 nrm = cross(b - a, c - a);
    vec3 an = abs(nrm);
    // w: the normal's dominant axis; u, v the other two. The plane is
    // w = (dp - nrm_u u - nrm_v v) / nrm_w.
    int w = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
    int ua = (w + 1) % 3, va = (w + 2) % 3;
    // The triangle's own (u, v) columns, in tiles of VISIBILITY_TILE^2;
    // this invocation takes every tiles-th of them from its own
    // (gl_GlobalInvocationID.y of the dispatch's y = tiles).
    int tiles_u = (chi[ua] - clo[ua]) / VISIBILITY_TILE + 1;
    int count = tiles_u * ((chi[va] - clo[va]) / VISIBILITY_TILE + 1);
    int stride = int(gl_NumWorkGroups.y);
    float dp = dot(nrm, a);
    float su = -nrm[ua] / nrm[w], sv = -nrm[va] / nrm[w], s0 = dp / nrm[w];
    for (int tile = int(gl_GlobalInvocationID.y); tile < count; tile += stride) {
        int u0 = clo[ua] + (tile % tiles_u) * VISIBILITY_TILE;
        int v0 = clo[va] + (tile / tiles_u) * VISIBILITY_TILE;
        int u1 = min(chi[ua], u0 + VISIBILITY_TILE - 1), v1 = min(chi[va], v0 + VISIBILITY_TILE - 1);
        for (int cu = u0; cu <= u1; ++cu) {
            for (int cv = v0; cv <= v1; ++cv) {
                // The plane's w over the column [cu, cu + 1] x [cv, cv + 1]:
                // linear, so its extremes are at the corners.
                float w00 = s0 + su * float(cu) + sv * float(cv);
                float wlo = w00 + min(su, 0.0) + min(sv, 0.0) - MARGIN;
                float whi = w00 + max(su, 0.0) + max(sv, 0.0) + MARGIN;
                int w0 = max(clo[w], int(floor(wlo))), w1 = min(chi[w], int(floor(whi)));
                for (int cw = w0; cw <= w1; ++cw) {
                    ivec3 cell;
                    cell[ua] = cu;
                    cell[va] = cv;
                    cell[w] = cw;
                    if (touches(cell, a, b, c)) set_sub_cell(cell);
                }
            }
        }
    }
}

void main() {
    uint t = gl_GlobalInvocationID.x;
    if (t >= draw.triangles) return;
    uint first = draw.first_index + 3u * (draw.first_triangle + t);
    mat4 m = transforms[draw.instance].world_from_object;
    vec4 g = u.visibility_grid;
    float per = float(GRID_SUB) / g.w;  // sub-cells per unit of length
    vec3 a = ((m * vec4(vertex_position(index_data[first]), 1.0)).xyz - g.xyz) * per;
    vec3 b = ((m * vec4(vertex_position(index_data[first + 1u]), 1.0)).xyz - g.xyz) * per;
    vec3 c = ((m * vec4(vertex_position(index_data[first + 2u]), 1.0)).xyz - g.xyz) * per;
    vec3 nrm = cross(b - a, c - a);
    // A triangle without area hides nothing (and has no plane).
    if (!(dot(nrm, nrm) > 1e-20)) return;
    mark(a, b, c);
}
