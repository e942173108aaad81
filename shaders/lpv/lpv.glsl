// Method lpv (Cascaded Light Propagation Volumes, Kaplanyan & Dachsbacher,
// I3D 2010; docs/algorithm.md section 8): what every LPV shader shares. The
// grid layout, the cascades' placement and the 2-band spherical harmonics.
// Include after frame.glsl.
//
// Specialisation constants (every LPV pipeline sets them from the run's
// settings; src/methods/lpv/ is their one writer):
//   0 LPV_SIZE      cells per side of a cascade (a power of two)
//   1 LPV_CASCADES  nested cascades, finest first
#ifndef LPV_GLSL
#define LPV_GLSL

layout(constant_id = 40) const int LPV_SIZE = 32;
layout(constant_id = 41) const int LPV_CASCADES = 3;

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
// The scene's reach from the camera: the power of two at or above the
// distance from the camera to the farthest corner of the scene's bounds
// (the frame uniforms carry it as normal_depth_scale = 2^15 / reach). The
// coarsest cascade's side is the reach; each finer one halves it. Every
// factor is a power of two, so cell sizes are exact and a scene scaled by a
// power of two makes the same grid.
float lpv_cell_size(int c) {
    float reach = 32768.0 / u.normal_depth_scale;
    return reach * exp2(float(c - (LPV_CASCADES - 1))) / float(LPV_SIZE);
}

// Cascade c's first cell, in whole cells of its size from the render origin:
// its centre lies 3/8 of its side ahead of the camera (an eighth of it behind
// the camera), snapped to whole cells, so the grid does not swim as the
// camera moves. `precise`: every shader computes the same cells.
ivec3 lpv_origin(int c) {
    float h = lpv_cell_size(c);
    precise vec3 centre = u.camera_position + u.camera_forward * (0.375 * float(LPV_SIZE) * h);
    return ivec3(floor(centre / h)) - ivec3(LPV_SIZE / 2);
}

// Point p in cascade c's cell coordinates: cell i spans [i, i + 1).
vec3 lpv_grid_position(int c, vec3 p) {
    return p / lpv_cell_size(c) - vec3(lpv_origin(c));
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
