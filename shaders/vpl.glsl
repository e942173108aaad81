// Light patches and their contribution to a receiver (docs/algorithm.md section 2).
#ifndef VPL_GLSL
#define VPL_GLSL
#include "voxel_grid/march.glsl"

// Whether the march is compiled in at all (src/passes/voxel_grid/voxelize.rs
// sets it from --visibility): a uniform branch around it cost lavapipe
// 1.3-2.7x on every gather and splat without the grid.
layout(constant_id = 20) const bool VOXEL_VISIBILITY = false;

// C_{j->i} / rho_i: the irradiance a patch with flux phi (W), world area a
// (m^2), position xj and unit normal nj, at level `level` (patch_level), gives
// a receiver at xi with unit normal ni, with the disc form factor that stays
// finite as the distance goes to 0:
//   E = phi * cos_i * cos_j / (pi * d^2 + A_j) * V_ij
// A merged patch on one surface (level > 0) stands for texels spread over its area; with
// PATCH_KERNEL_SECOND_ORDER the mean of the point kernel over a disc of area
// A_j about xj replaces its value at xj, to second order in the disc's radius
// over d (docs/algorithm.md section 2.6 derives it):
//   k = [cos_i cos_j (1 + f (3 sin_j^2 - 1)) - f cos_j^2 (ni . nj)] / (pi d^2 + A_j),
//   f = A_j / (pi d^2 + A_j), sin_j^2 = 1 - cos_j^2,
// clamped to [0, 1 / (pi d^2 + A_j)] (the cosines' bound every test on the
// contribution uses: HISR's absolute tau, the restricted splats' quads).
// V_ij the visibility term every method shares (run.visibility: 1 without,
// the voxel grid's 0 to 1 with --visibility voxels; docs/algorithm.md
// section 5, "Voxel visibility"). The march runs for every pair, not only
// where the rest is not 0, so that a list's fragments march together
// (one march's loop at a time: lavapipe's loop limit, voxel_grid/march.glsl).
// patch_unshadowed is E without V_ij, for a caller that finds V_ij itself
// (HISR's tile-shared visibility, hisr/gather.frag).
vec3 patch_unshadowed(vec3 xi, vec3 ni, vec3 xj, vec3 nj, vec3 phi, float a, int level) {
    vec3 v = xj - xi;
    float d2 = dot(v, v);
    vec3 dir = v * inversesqrt(max(d2, 1e-30));
    float cos_i = max(dot(ni, dir), 0.0);
    float cos_j = max(-dot(nj, dir), 0.0);
    float denominator = PI * d2 + a;
    float k = cos_i * cos_j / denominator;
    if (level > 0 && run.patch_kernel == PATCH_KERNEL_SECOND_ORDER && k > 0.0) {
        float f = a / denominator;
        float second = cos_i * cos_j * (1.0 + f * (2.0 - 3.0 * cos_j * cos_j)) - f * cos_j * cos_j * dot(ni, nj);
        k = clamp(second / denominator, 0.0, 1.0 / denominator);
    }
    return phi * k;
}

vec3 patch_irradiance(vec3 xi, vec3 ni, vec3 xj, vec3 nj, vec3 phi, float a, int level) {
    vec3 e = patch_unshadowed(xi, ni, xj, nj, phi, a, level);
    if (VOXEL_VISIBILITY) e *= voxel_visibility(xi, ni, xj, nj, a);
    return e;
}

#endif
