// Indirect visibility through the voxel occupancy grid (docs/algorithm.md
// section 5, "Voxel visibility"): whether the segment from a receiver to a
// light patch crosses an occupied cell. The grid is this frame's posed
// scene, conservatively voxelized by voxel_grid/voxelize.comp: N^3 finest cells
// over the cube u.grid_cube, and OR-levels k = 1.. of side N >> k
// (a level-k cell is occupied iff one of its 8^k finest cells is:
// voxel_grid/levels.comp), laid out as voxel_grid/layout.glsl says.
#ifndef VISIBILITY_GLSL
#define VISIBILITY_GLSL
#include "voxel_grid/layout.glsl"

// Read two words at a time: a finest cell's sub-cell mask, or the pair of
// words that holds a coarser cell's bit (voxel_grid/layout.glsl).
layout(set = 0, binding = 3, std430) readonly buffer GridOccupancy { uvec2 visibility_pairs[]; };

// The parts of the segment nearer than this to the receiver's tangent plane
// (in finest cells) are not marched: the sub-cells a plane touches lie within
// a sub-cell's diagonal, sqrt(3) / GRID_SUB cells, of it, so a point farther
// than that from the receiver's own plane is never in a sub-cell that plane
// made occupied. What it skips is a length of about 1.75 / GRID_SUB cells /
// cos: grazing pairs skip most, and they are the ones the cosines weigh
// least. Sub-cells are what let it be short: over the 1.75 cells that a
// whole cell's diagonal needs, the blinds of `slats` let through 0.2-0.35 of
// their light (docs/algorithm.md section 5, "Sub-cells").
// (A macro: a constant made from a specialization constant cannot be a float.)
#define VISIBILITY_END_SKIP (1.75 / float(GRID_SUB))

// At the patch's end the skip is its disc's radius, between the receiver's
// skip and a whole cell's 1.75: a coarse patch's mean position lies off the
// surfaces its texels are on by up to about its radius, and a short skip
// there shadowed such patches by their own geometry.
const float VISIBILITY_PATCH_SKIP = 1.75;

// Lavapipe (gallivm) ends every loop of a shader invocation once they have
// run 65,535 iterations together, without a word: a fragment that gathers E
// patches may take E (MAX_ITERATIONS + 1) iterations for the marches, so
// each march is at most VISIBILITY_MAX_ITERATIONS iterations of
// six cells entered or levels changed each (docs/algorithm.md section 5,
// "Voxel visibility", has the bound per method). A march that has not ended
// by then counts what it has found so far.
const int VISIBILITY_MAX_ITERATIONS = 13;

// What blocks: the segment's length inside occupied sub-cells, in cells.
// Visibility is 1 - that length / VISIBILITY_OPAQUE_CHORD, clamped to [0, 1]:
// a segment that crosses a surface passes through at least a sub-cell's
// worth of the sub-cells it made occupied (those within sqrt 3 sub-cells of
// it, one layer at least), so it is blocked whole, while one that only clips
// a sub-cell's corner or edge
// loses in proportion, and as a patch or receiver moves its visibility changes
// continuously instead of flipping from 1 to 0 at a cell boundary
// (docs/algorithm.md section 5, "Voxel visibility").
#define VISIBILITY_OPAQUE_CHORD (0.5 / float(GRID_SUB))

// Points per level-0 chord at which the sub-cells are tested. Along each axis
// they lie at most a quarter of the chord's extent apart, and so at most a
// quarter of a cell: none passes a layer of sub-cells of GRID_SUB 4 across
// an axis without a point inside it. Eight points instead read within 0.006
// of four against the truth and cost 1.15x the gather (docs/algorithm.md
// section 5, "Sub-cells").
const int VISIBILITY_SAMPLES = 4;

// The visibility of the part t0..t1 of the segment xi -> xj (fractions of
// it from xi): 1 where it crosses no occupied sub-cell, 0 where it runs at
// least VISIBILITY_OPAQUE_CHORD cells through them, linear between. A
// hierarchical DDA:
// at each point, the coarsest level whose cell there is empty is skipped
// whole (found from level 1 up); an occupied cell is entered one level finer;
// an occupied finest cell adds its chord times the fraction of
// VISIBILITY_SAMPLES points evenly along the chord that lie in occupied
// sub-cells; after leaving a cell the march climbs a level only where it also
// left the parent cell.
float voxel_march(vec3 xi, vec3 xj, float t0, float t1) {
    vec4 g = u.grid_cube;
    vec3 a = (xi - g.xyz) / g.w;  // in finest cells
    vec3 d = (xj - xi) / g.w;
    // No zero components: the exit distances below stay finite and ordered.
    vec3 ds = mix(d, vec3(1e-12), lessThan(abs(d), vec3(1e-12)));
    vec3 inv = 1.0 / ds;
    // Only the grid's inside holds occluders.
    float side = float(run.grid_side);
    vec3 ta = -a * inv, tb = (vec3(side) - a) * inv;
    vec3 tin = min(ta, tb), tout = max(ta, tb);
    t0 = max(t0, max(tin.x, max(tin.y, tin.z)));
    t1 = min(t1, min(tout.x, min(tout.y, tout.z)));
    ivec3 ahead = ivec3(greaterThan(ds, vec3(0.0)));
    vec3 a_inv = a * inv;          // a cell face f is left at t = f inv - a_inv
    float seg = length(d);         // the segment's length in cells
    float eps = 1e-3 / seg;        // a thousandth of a cell along the segment
    int top = run.grid_levels - 1;
    // Start one level up: the march starts near the receiver's surface,
    // where the coarse cells are occupied (it climbs as it leaves parents).
    int k = min(1, top);
    float t = t0;
    ivec3 last_cell = ivec3(run.grid_side - 1);
    float inside = 0.0;  // the segment's length inside occupied finest cells
    bool going = t < t1;
    // The finest cell at t: found once per advance, and kept while the march
    // only changes level there.
    ivec3 f = clamp(ivec3(floor(a + t * d)), ivec3(0), last_cell);
    // One cell entered or one level changed. The cell at t was entered at t
    // (less the thousandth of a cell the last advance stepped past its face,
    // or at t0), so an occupied cell's chord runs from t to where the march
    // leaves it. Level k + 1's cell changes where f's bits above k do.
    // The step has no branches: every lane computes both outcomes and keeps
    // its own by selects. On lavapipe the branched step (a descent or an
    // advance, inside `if (going)`) took HISR's indirect time with the grid
    // to 1.12-1.25x this one's: gallivm stored every variable a branch
    // changed under the lane mask (docs/algorithm.md section 5, "The
    // march's step without branches"). The grid's word is read for every
    // lane alike.
    // A sample of the chord at level 0: whether the point a fraction
    // (j + 0.5) / VISIBILITY_SAMPLES along it lies in an occupied sub-cell of
    // the mask w. q, dq in sub-cells from the cell's corner; the points lie
    // inside the cell (truncation is the floor there) but where the chord is
    // a few ulps long, and then what they add is as small.
#define VISIBILITY_SAMPLE(j)                                                         \
    {                                                                                \
        vec3 p = trunc(q + (float(j) + 0.5) * dq);                                   \
        uint b = uint(p.x + float(GRID_SUB) * (p.y + float(GRID_SUB) * p.z));       \
        hits += (((b & 32u) != 0u ? w.y : w.x) >> (b & 31u)) & 1u;                   \
    }
#define VISIBILITY_STEP                                                              \
    {                                                                                \
        ivec3 c = f >> k;                                                            \
        uint i = grid_cell_index(k, c);                                              \
        bool masks = k == 0 && GRID_SUB > 1;                                         \
        uvec2 w = visibility_pairs[masks ? i : (grid_level_offset(k) >> 1u) + (i >> 6u)]; \
        uint word = (i & 32u) != 0u ? w.y : w.x;                                     \
        bool occupied = masks ? (w.x | w.y) != 0u : ((word >> (i & 31u)) & 1u) != 0u; \
        bool down = occupied && k > 0;                                               \
        vec3 far = vec3((c + ahead) << k) * inv - a_inv;                             \
        float leave = min(far.x, min(far.y, far.z));                                 \
        bool advance = going && !down;                                               \
        float tl = min(leave, t1);                                                   \
        float chord = (tl - t) * seg;                                                \
        uint hits = uint(VISIBILITY_SAMPLES);                                        \
        if (GRID_SUB > 1) {                                                          \
            vec3 q = (a + t * d - vec3(c)) * float(GRID_SUB);                        \
            vec3 dq = (tl - t) * d * (float(GRID_SUB) / float(VISIBILITY_SAMPLES));  \
            hits = 0u;                                                               \
            VISIBILITY_SAMPLE(0) VISIBILITY_SAMPLE(1)                                \
            VISIBILITY_SAMPLE(2) VISIBILITY_SAMPLE(3)                                \
        }                                                                            \
        /* An occupied cell is one of level 0 where the march advances. */           \
        inside += (advance && occupied) ? chord * float(hits) / float(VISIBILITY_SAMPLES) : 0.0; \
        float tn = max(t, leave) + eps;                                              \
        ivec3 next = clamp(ivec3(floor(a + tn * d)), ivec3(0), last_cell);           \
        ivec3 moved = (next ^ f) >> (k + 1);                                         \
        bool up = k < top && (moved.x | moved.y | moved.z) != 0;                     \
        k = (going && down) ? k - 1 : ((advance && up) ? k + 1 : k);                 \
        t = advance ? tn : t;                                                        \
        f = advance ? next : f;                                                      \
        going = going && (down || (tn < t1 && inside < VISIBILITY_OPAQUE_CHORD));    \
    }
    for (int i = 0; i < VISIBILITY_MAX_ITERATIONS && going; ++i) {
        VISIBILITY_STEP
        VISIBILITY_STEP
        VISIBILITY_STEP
        VISIBILITY_STEP
        VISIBILITY_STEP
        VISIBILITY_STEP
    }
#undef VISIBILITY_STEP
#undef VISIBILITY_SAMPLE
    return clamp(1.0 - inside / VISIBILITY_OPAQUE_CHORD, 0.0, 1.0);
}

// Where the march of xi -> xj starts, as a fraction of the segment: past
// the receiver's skip (VISIBILITY_END_SKIP over the receiver's plane; ni its
// unit normal, the rise over its plane being where the contribution is not 0).
float voxel_receiver_skip(vec3 xi, vec3 ni, vec3 xj) {
    float rise_i = dot((xj - xi) / u.grid_cube.w, ni);
    return VISIBILITY_END_SKIP / max(rise_i, 1e-30);
}

// Where the march of xi -> xj ends, as a fraction of the segment: short of
// the patch's skip (its disc's radius over its plane; nj its unit normal, aj
// its area).
float voxel_patch_skip(vec3 xi, vec3 xj, vec3 nj, float aj) {
    float rise_j = -dot((xj - xi) / u.grid_cube.w, nj);
    float skip_j = clamp(sqrt(aj / PI) / u.grid_cube.w, VISIBILITY_END_SKIP, VISIBILITY_PATCH_SKIP);
    return 1.0 - skip_j / max(rise_j, 1e-30);
}

// The visibility of the segment xi -> xj outside the two ends' skipped parts:
// 1 where it crosses no occupied sub-cell, 0 where it runs at least
// VISIBILITY_OPAQUE_CHORD cells through them, linear between. ni, nj: unit
// normals of the receiver and the patch; aj the patch's area.
float voxel_visibility(vec3 xi, vec3 ni, vec3 xj, vec3 nj, float aj) {
    return voxel_march(xi, xj, voxel_receiver_skip(xi, ni, xj), voxel_patch_skip(xi, xj, nj, aj));
}

#endif
