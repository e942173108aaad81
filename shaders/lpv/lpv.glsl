// Method lpv (Cascaded Light Propagation Volumes, Kaplanyan & Dachsbacher,
// I3D 2010; docs/algorithm.md section 8): what every LPV shader shares. The
// grid layout, the cascades' placement and the 2-band spherical harmonics.
// Include after frame.glsl.
//
// Specialisation constants (every LPV pipeline sets them from the run's
// settings; src/methods/lpv/ is their one writer):
//   0 LPV_SIZE      cells per side of a cascade (a power of two)
//   1 LPV_CASCADES  nested cascades, finest first
//   2 LPV_AHEAD     how far ahead of the camera a cascade's centre aims, in
//                   sides (grid::AHEAD)
#ifndef LPV_GLSL
#define LPV_GLSL

layout(constant_id = 40) const int LPV_SIZE = 32;
layout(constant_id = 41) const int LPV_CASCADES = 3;
layout(constant_id = 46) const float LPV_AHEAD = 0.375;

// Cells of all cascades: cascade c, cell (x, y, z) is cell
// ((c * N + z) * N + y) * N + x. The injection images are 2D arrays of
// N x N texels and N * C layers (layer c * N + z), so a copy of one into a
// buffer lays its cells out in this order.
const int LPV_CELLS = LPV_SIZE * LPV_SIZE * LPV_SIZE * LPV_CASCADES;

int lpv_cell_index(int c, ivec3 cell) {
    return ((c * LPV_SIZE + cell.z) * LPV_SIZE + cell.y) * LPV_SIZE + cell.x;
}

// --- Placement (docs/algorithm.md section 8.1) ---
//
// Fitted to the scene's bounds (u.scene_min, u.scene_max) and the camera.
// The coarsest cascade holds the scene: its cell is the smallest power of
// two h with (N - 3) h >= the bounds' largest side, so that it spans them
// with a cell to spare on each side (two below, one above, as the snap
// falls). Each finer cascade halves the cell. Powers of two keep every
// product and quotient exact (the host, every shader and every stage place
// alike) and a scene scaled by a power of two makes the same grids.
//
// The coarsest cascade's cell, as an exponent: the smallest k with
// (N - 3) 2^k >= the largest side (0 for an empty scene). log2 is only
// approximate; the exact comparisons settle k.
int lpv_top_exponent() {
    vec3 e = u.scene_max - u.scene_min;
    float side = max(max(e.x, e.y), e.z);
    if (!(side > 0.0)) return 0;
    float room = float(LPV_SIZE - 3);
    int k = int(ceil(log2(side / room)));
    if (ldexp(room, k - 1) >= side) k -= 1;
    if (ldexp(room, k) < side) k += 1;
    return k;
}

// Cascade c's cell exponent: the coarsest's, halved per cascade finer.
int lpv_exponent(int c) {
    return lpv_top_exponent() + c - (LPV_CASCADES - 1);
}

float lpv_cell_size(int c) {
    return ldexp(1.0, lpv_exponent(c));
}

// Cascade c's first cell, in whole cells from the scene's min corner. Its
// centre aims LPV_AHEAD of its side ahead of the camera, moved (per axis)
// as little as keeps the cascade inside the bounds widened by a cell, or
// at their middle where it is wider than that; then snapped to whole cells
// of a lattice fixed to the scene, so the grid does not swim as the camera
// moves. A camera outside the bounds gets the cascades on the scene's side
// nearest it. `precise`: every shader computes the same cells.
ivec3 lpv_origin(int c) {
    int k = lpv_exponent(c);
    float h = ldexp(1.0, k);
    float side = float(LPV_SIZE) * h;
    precise vec3 aim = u.camera_position + u.camera_forward * (LPV_AHEAD * side);
    precise vec3 lo = u.scene_min - h + 0.5 * side;
    precise vec3 hi = u.scene_max + h - 0.5 * side;
    precise vec3 middle = 0.5 * (u.scene_min + u.scene_max);
    vec3 centre = mix(min(max(aim, lo), hi), middle, lessThan(hi, lo));
    precise vec3 cells = (centre - u.scene_min) * ldexp(1.0, -k);
    return ivec3(floor(cells)) - ivec3(LPV_SIZE / 2);
}

// Point p in cascade c's cell coordinates: cell i spans [i, i + 1).
vec3 lpv_grid_position(int c, vec3 p) {
    precise vec3 g = (p - u.scene_min) * ldexp(1.0, -lpv_exponent(c)) - vec3(lpv_origin(c));
    return g;
}

bool lpv_inside(ivec3 cell) {
    return all(greaterThanEqual(cell, ivec3(0))) && all(lessThan(cell, ivec3(LPV_SIZE)));
}

// --- 2-band spherical harmonics: vec4(c0, cx, cy, cz) ---
//
// Basis: Y0 = 1 / (2 sqrt(pi)), Y1(w) = sqrt(3 / (4 pi)) (x, y, z).
const float SH_Y0 = 0.28209479177387814;
const float SH_Y1 = 0.4886025119029199;
// Projection of the clamped cosine max(0, n.w): sqrt(pi) / 2 and sqrt(pi / 3).
const float SH_COS0 = 0.886226925452758;
const float SH_COS1 = 1.0233267079464885;
// The integral of a function over the sphere is c0 * 2 sqrt(pi).
const float SH_FLUX = 3.5449077018110318;

float sh_eval(vec4 f, vec3 w) {
    return f.x * SH_Y0 + SH_Y1 * dot(f.yzw, w);
}

// max(0, n.w) projected (n a unit vector, or 0 for an isotropic lobe of
// the same integral, pi).
vec4 sh_cosine_lobe(vec3 n) {
    return vec4(SH_COS0, SH_COS1 * n);
}

#endif
