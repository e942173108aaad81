// Indirect visibility through the voxel occupancy grid (docs/algorithm.md
// section 5, "Voxel visibility"): whether the segment from a receiver to a
// light patch crosses an occupied cell. The grid is this frame's posed
// scene, conservatively voxelized by visibility_grid.comp: N^3 finest cells
// over the cube u.visibility_grid, and OR-levels k = 1.. of side N >> k
// (a level-k cell is occupied iff one of its 8^k finest cells is:
// visibility_grid_levels.comp), laid out as visibility_layout.glsl says.
#ifndef VISIBILITY_GLSL
#define VISIBILITY_GLSL
#include "visibility_layout.glsl"

layout(set = 0, binding = 3, std430) readonly buffer VisibilityGrid { uint visibility_bits[]; };

bool grid_occupied(int k, ivec3 c) { return (visibility_bits[grid_word(k, c)] & grid_bit(k, c)) != 0u; }

// The parts of the segment nearer than this to either end's tangent plane
// (in finest cells) are not marched: the cells a plane touches lie within a
// cell's diagonal, sqrt(3), of it, so a point farther than that from the
// receiver's (or the patch's) own plane is never in a cell that plane made
// occupied. What it skips is a length of about 1.75 cells / cos: grazing
// pairs skip most, and they are the ones the cosines weigh least.
const float VISIBILITY_END_SKIP = 1.75;

// Lavapipe (gallivm) ends every loop of a shader invocation once they have
// run 65,535 iterations together, without a word: a fragment that gathers E
// patches may take E (MAX_ITERATIONS + 1) iterations for the marches, so
// each march is at most VISIBILITY_MAX_ITERATIONS iterations of
// six cells entered or levels changed each (docs/algorithm.md section 5,
// "Voxel visibility", has the bound per method). A march that has not ended
// by then counts what it has found so far.
const int VISIBILITY_MAX_ITERATIONS = 13;

// What blocks: the segment's length inside occupied finest cells, in cells.
// Visibility is 1 - that length / VISIBILITY_OPAQUE_CHORD, clamped to [0, 1]:
// a segment that crosses a surface passes through at least a cell's worth of
// the cells it made occupied (those within sqrt 3 of it, one layer at least),
// so it is blocked whole, while one that only clips a cell's corner or edge
// loses in proportion, and as a patch or receiver moves its visibility changes
// continuously instead of flipping from 1 to 0 at a cell boundary
// (docs/algorithm.md section 5, "Voxel visibility").
const float VISIBILITY_OPAQUE_CHORD = 0.5;

// The visibility of the segment xi -> xj outside the two ends' skipped parts:
// 1 where it crosses no occupied finest cell, 0 where it runs at least
// VISIBILITY_OPAQUE_CHORD cells through them, linear between. ni, nj: unit
// normals of the receiver and the patch (the rise over each one's plane is
// where the contribution is not 0). A hierarchical DDA: at each point, the
// coarsest level whose cell there is empty is skipped whole (found from level
// 1 up); an occupied cell is entered one level finer; an occupied finest cell
// adds its chord; after leaving a cell the march climbs a level only where it
// also left the parent cell.
float voxel_visibility(vec3 xi, vec3 ni, vec3 xj, vec3 nj) {
    vec4 g = u.visibility_grid;
    vec3 a = (xi - g.xyz) / g.w;  // in finest cells
    vec3 d = (xj - xi) / g.w;
    float rise_i = dot(d, ni);    // the patch's height over the receiver's plane
    float rise_j = -dot(d, nj);   // the receiver's height over the patch's plane
    float t0 = VISIBILITY_END_SKIP / max(rise_i, 1e-30);
    float t1 = 1.0 - VISIBILITY_END_SKIP / max(rise_j, 1e-30);
    // No zero components: the exit distances below stay finite and ordered.
    vec3 ds = mix(d, vec3(1e-12), lessThan(abs(d), vec3(1e-12)));
    vec3 inv = 1.0 / ds;
    // Only the grid's inside holds occluders.
    float side = float(run.visibility_side);
    vec3 ta = -a * inv, tb = (vec3(side) - a) * inv;
    vec3 tin = min(ta, tb), tout = max(ta, tb);
    t0 = max(t0, max(tin.x, max(tin.y, tin.z)));
    t1 = min(t1, min(tout.x, min(tout.y, tout.z)));
    ivec3 ahead = ivec3(greaterThan(ds, vec3(0.0)));
    vec3 a_inv = a * inv;          // a cell face f is left at t = f inv - a_inv
    float seg = length(d);         // the segment's length in cells
    float eps = 1e-3 / seg;        // a thousandth of a cell along the segment
    int top = run.visibility_levels - 1;
    // Start one level up: the march starts near the receiver's surface,
    // where the coarse cells are occupied (it climbs as it leaves parents).
    int k = min(1, top);
    float t = t0;
    ivec3 last_cell = ivec3(run.visibility_side - 1);
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
#define VISIBILITY_STEP                                                              \
    {                                                                                \
        ivec3 c = f >> k;                                                            \
        bool occupied = grid_occupied(k, c);                                         \
        bool down = occupied && k > 0;                                               \
        vec3 far = vec3((c + ahead) << k) * inv - a_inv;                             \
        float leave = min(far.x, min(far.y, far.z));                                 \
        bool advance = going && !down;                                               \
        float chord = (min(leave, t1) - t) * seg;                                    \
        inside += (advance && occupied) ? chord : 0.0;                               \
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
    return clamp(1.0 - inside / VISIBILITY_OPAQUE_CHORD, 0.0, 1.0);
}

#endif
