#version 460
// Pass visibility-grid, its first dispatches (docs/algorithm.md section 5,
// "Voxel visibility"): the finest level of the occupancy grid of this
// frame's posed scene, from one instance's triangles (placed by this frame's
// InstanceTransform). Every sub-cell (finest cell, without sub-cells) a
// triangle touches gets its bit set with atomicOr, so the result does not
// depend on the order triangles run in. The coarser levels are ORs of this
// one, made after it by voxel_grid/levels.comp (voxelizing every level
// here took about 70% of the pass on the 277k triangles of the conference
// room).
//
// The test is the separating-axis test of a triangle and a box (Akenine-Moller
// 2001), made conservative by a small margin: the box's face normals come
// from visiting only the cells of the triangle's bounding box, the
// triangle's normal from visiting, in each column along the dominant axis of
// the normal, only the cells the plane crosses over that column; the nine
// axes edge x box-axis are tested per cell, except where the column lies
// inside the triangle's outline, where they cannot separate (mark_column).
//
// Who marks what (voxel_grid/voxelize.rs): each mesh's triangles are ordered
// largest first (TriangleOrder), and each frame the large ones of each
// instance, those that may span more than 64 sub-cells a side (walls,
// floors), are marked by a dispatch of this shader with LARGE true, in which
// a workgroup's 64 invocations take one triangle's columns at a time and the
// dispatch's y rows of workgroups share each; the others by one with LARGE
// false, each by its own invocation, beside triangles of about its own size.
// Lavapipe runs 8 invocations together: with a triangle per invocation and
// the meshes' own order, a group that held one wall ran as long as the
// wall's columns, and every row of workgroups loaded every triangle to mark
// its share of the few large ones (docs/algorithm.md section 5, "Sub-cells":
// the pass took 17-25 ms on the Cornell box's 34 triangles at grid 64 with 4
// sub-cells, 76 ms on the conference room's 278k). Lavapipe also ends an
// invocation's loops after 65,535 iterations together: a small triangle has
// at most 66 x 66 columns, and y is large enough that no invocation takes
// more than 128 columns of a large one.
#extension GL_GOOGLE_include_directive : require
#include "voxel_grid/layout.glsl"
layout(local_size_x = 64) in;

// Cleared before the dispatch (voxel_grid/voxelize.rs).
layout(set = 0, binding = 3, std430) buffer GridOccupancy { uint visibility_bits[]; };
layout(set = 1, binding = 0, std430) readonly buffer Vertices { float vertex_data[]; };  // GpuVertex: 8 floats
layout(set = 1, binding = 1, std430) readonly buffer Indices { uint index_data[]; };
layout(push_constant) uniform Push { VoxelizePush draw; };

// In cells: covers float error in the corners and faces the tests compare.
const float MARGIN = 1e-3;

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

// A triangle a, b, c (in sub-cells) set up for its columns, in the axes
// (u, v, w), w the normal's dominant axis: its bounding sub-cells lo .. hi,
// its plane as w = s0 + su u + sv v, its three edges in the (u, v) plane as
// e.x u + e.y v + e.z, positive inside, and the grid's axes of u, v and w
// (cell = U u + V v + W w). The axes are chosen once per triangle: a vector
// component picked by a different index in each lane is a slow gather on
// lavapipe.
struct Columns {
    vec3 a, b, c;
    ivec3 lo, hi;
    ivec3 U, V, W;
    float su, sv, s0;
    vec3 e0, e1, e2;
};

// x, y, z of p in the axes (u, v, w) of dominant axis w.
vec3 in_uvw(vec3 p, int w) { return w == 0 ? p.yzx : (w == 1 ? p.zxy : p.xyz); }

// The columns of a, b, c; `count` 0 where it lies outside the grid.
Columns columns_of(vec3 a, vec3 b, vec3 c, out uint count) {
    Columns t;
    t.a = a;
    t.b = b;
    t.c = c;
    int n = run.grid_side * GRID_SUB;
    vec3 lo = min(a, min(b, c)) - MARGIN, hi = max(a, max(b, c)) + MARGIN;
    bool outside = any(lessThan(hi, vec3(0.0))) || any(greaterThanEqual(lo, vec3(float(n))));
    vec3 an = abs(cross(b - a, c - a));
    int w = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
    t.lo = clamp(ivec3(floor(in_uvw(lo, w))), ivec3(0), ivec3(n - 1));
    t.hi = clamp(ivec3(floor(in_uvw(hi, w))), ivec3(0), ivec3(n - 1));
    // The grid's axis of u, v and w: u = (w + 1) % 3, v = (w + 2) % 3.
    t.W = ivec3(equal(ivec3(0, 1, 2), ivec3(w)));
    t.U = ivec3(equal(ivec3(0, 1, 2), ivec3((w + 1) % 3)));
    t.V = ivec3(equal(ivec3(0, 1, 2), ivec3((w + 2) % 3)));
    vec3 pa = in_uvw(a, w), pb = in_uvw(b, w), pc = in_uvw(c, w);
    vec3 nrm = cross(pb - pa, pc - pa);  // the normal in (u, v, w): its z dominant
    t.su = -nrm.x / nrm.z;
    t.sv = -nrm.y / nrm.z;
    t.s0 = dot(nrm, pa) / nrm.z;
    // nrm.z is the (u, v) cross product of the edges: its sign orients them.
    float o = sign(nrm.z);
    vec2 d0 = pb.xy - pa.xy, d1 = pc.xy - pb.xy, d2 = pa.xy - pc.xy;
    t.e0 = o * vec3(-d0.y, d0.x, d0.y * pa.x - d0.x * pa.y);
    t.e1 = o * vec3(-d1.y, d1.x, d1.y * pb.x - d1.x * pb.y);
    t.e2 = o * vec3(-d2.y, d2.x, d2.y * pc.x - d2.x * pc.y);
    count = outside ? 0u : uint(t.hi.x - t.lo.x + 1) * uint(t.hi.y - t.lo.y + 1);
    return t;
}

// Where the square [cu, cu + 1] x [cv, cv + 1] lies against edge e (e is
// linear: its extremes there are at corners): x, whether inside it by more
// than MARGIN sub-cells; y, whether outside it by more than 2 MARGIN. A
// column outside one edge by MARGIN is outside the triangle's outline, so
// that edge's axis (e x w, one of the nine) separates each of its cells,
// grown by MARGIN, from the triangle: twice the margin keeps that from
// depending on how touches() rounds.
bvec2 square_against(vec3 e, float cu, float cv) {
    float at = e.x * cu + e.y * cv + e.z;
    float m = MARGIN * (abs(e.x) + abs(e.y));
    return bvec2(at + min(e.x, 0.0) + min(e.y, 0.0) > m, at + max(e.x, 0.0) + max(e.y, 0.0) < -2.0 * m);
}

// Marks the sub-cells of column (cu, cv) that the triangle touches, among
// those the plane crosses over the column or reaches within MARGIN. Where
// the column lies inside the triangle's (u, v) outline, every sub-cell the
// plane itself crosses there touches the triangle (the plane's points over
// the column are the triangle's), so only those it reaches within the
// margin alone are tested; outside the outline, none; elsewhere every one
// is. Two loops, not a branch per sub-cell: lavapipe runs a branch's body
// for a whole group of lanes whatever they take, but leaves a loop once no
// lane has an iteration left.
void mark_column(Columns t, int cu, int cv) {
    // The plane's w over the column: linear, so its extremes are at the corners.
    float w00 = t.s0 + t.su * float(cu) + t.sv * float(cv);
    float wmin = w00 + min(t.su, 0.0) + min(t.sv, 0.0);
    float wmax = w00 + max(t.su, 0.0) + max(t.sv, 0.0);
    int w0 = max(t.lo.z, int(floor(wmin - MARGIN)));
    bvec2 s0 = square_against(t.e0, float(cu), float(cv));
    bvec2 s1 = square_against(t.e1, float(cu), float(cv));
    bvec2 s2 = square_against(t.e2, float(cu), float(cv));
    bool inside = s0.x && s1.x && s2.x;
    int w1 = s0.y || s1.y || s2.y ? w0 - 1 : min(t.hi.z, int(floor(wmax + MARGIN)));
    // Inside the outline, sub-cells sure0 .. sure1 are crossed by the plane.
    int sure0 = inside ? max(w0, int(floor(wmin))) : w1 + 1;
    int sure1 = inside ? min(w1, int(floor(wmax))) : w1;
    ivec3 column = t.U * cu + t.V * cv;
    for (int cw = sure0; cw <= sure1; ++cw) set_sub_cell(column + t.W * cw);
    // The others, tested: w0 .. sure0 - 1, then sure1 + 1 .. w1.
    int tested = (w1 - w0 + 1) - max(sure1 - sure0 + 1, 0);
    for (int i = 0; i < tested; ++i) {
        int cw = w0 + i;
        cw += cw >= sure0 ? sure1 - sure0 + 1 : 0;
        ivec3 cell = column + t.W * cw;
        if (touches(cell, t.a, t.b, t.c)) set_sub_cell(cell);
    }
}

// Which triangles this dispatch marks (voxel_grid/voxelize.rs): the large ones,
// those whose bounding box can span more than a few sub-cells a side, each
// by the whole workgroup, or the others, each by its own invocation.
layout(constant_id = 22) const bool LARGE = false;

// The mesh's triangles, largest first: each the position of its first index
// in Indices (voxel_grid/voxelize.rs, `TriangleOrder`), at the same place as the
// triangle's own (a draw's first index / 3 on).
layout(set = 1, binding = 2, std430) readonly buffer Order { uint triangle_order[]; };

// The workgroup's triangles, in sub-cells, for its invocations to share.
shared vec3 large_a[64], large_b[64], large_c[64];

// Triangle t of this dispatch in sub-cells of the grid, and whether it has
// an area (one without hides nothing and has no plane).
bool load_triangle(uint t, out vec3 a, out vec3 b, out vec3 c) {
    uint first = triangle_order[draw.first_index / 3u + draw.first_triangle + t];
    mat4 m = transforms[draw.instance].world_from_object;
    vec4 g = u.grid_cube;
    float per = float(GRID_SUB) / g.w;  // sub-cells per unit of length
    a = ((m * vec4(vertex_position(index_data[first]), 1.0)).xyz - g.xyz) * per;
    b = ((m * vec4(vertex_position(index_data[first + 1u]), 1.0)).xyz - g.xyz) * per;
    c = ((m * vec4(vertex_position(index_data[first + 2u]), 1.0)).xyz - g.xyz) * per;
    vec3 nrm = cross(b - a, c - a);
    return dot(nrm, nrm) > 1e-20;
}

void main() {
    uint t = gl_GlobalInvocationID.x;
    vec3 a, b, c;
    bool area = t < draw.triangles && load_triangle(t, a, b, c);
    if (!LARGE) {
        // A small triangle: its few columns (voxel_grid/voxelize.rs bounds them).
        if (!area) return;
        uint count;
        Columns s = columns_of(a, b, c, count);
        uint across = count == 0u ? 1u : uint(s.hi.x - s.lo.x + 1);
        for (uint j = 0u; j < count; ++j) {
            mark_column(s, s.lo.x + int(j % across), s.lo.y + int(j / across));
        }
        return;
    }
    // The workgroup's (up to) 64 large triangles, one after another, each
    // shared by its 64 invocations and by the dispatch's y rows of
    // workgroups: this invocation takes every (64 y)-th column from its own.
    // voxel_grid/voxelize.rs makes y large enough that none takes more than 128
    // columns of one: lavapipe ends an invocation's loops after 65,535
    // iterations together.
    uint i = gl_LocalInvocationIndex;
    large_a[i] = area ? a : vec3(0.0);
    large_b[i] = area ? b : vec3(0.0);
    large_c[i] = area ? c : vec3(0.0);
    barrier();
    uint here = min(64u, draw.triangles - gl_WorkGroupID.x * 64u);
    uint stride = 64u * gl_NumWorkGroups.y;
    for (uint k = 0u; k < here; ++k) {
        uint count;
        Columns l = columns_of(large_a[k], large_b[k], large_c[k], count);
        // A triangle without area (its corners set to 0 above) has no columns.
        vec3 n = cross(large_b[k] - large_a[k], large_c[k] - large_a[k]);
        count = dot(n, n) > 1e-20 ? count : 0u;
        uint across = uint(l.hi.x - l.lo.x + 1);
        for (uint j = i + 64u * gl_WorkGroupID.y; j < count; j += stride) {
            mark_column(l, l.lo.x + int(j % across), l.lo.y + int(j / across));
        }
    }
}
