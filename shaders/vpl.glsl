// Light patches and their contribution to a receiver (docs/algorithm.md section 2).
#ifndef VPL_GLSL
#define VPL_GLSL
#include "visibility.glsl"

// Whether the march is compiled in at all (src/passes/visibility_grid.rs
// sets it from --visibility): a uniform branch around it cost lavapipe
// 1.3-2.7x on every gather and splat without the grid.
layout(constant_id = 10) const bool VOXEL_VISIBILITY = false;

// C_{j->i} / rho_i: the irradiance a patch with flux phi (W), world area a
// (m^2), position xj and unit normal nj gives a receiver at xi with unit normal
// ni, with the disc form factor that stays finite as the distance goes to 0:
//   E = phi * cos_i * cos_j / (pi * d^2 + A_j) * V_ij
// V_ij the visibility term every method shares (run.visibility: 1 without,
// the voxel grid's 0 or 1 with --visibility voxels; docs/algorithm.md
// section 5, "Voxel visibility"). The march runs for every pair, not only
// where the rest is not 0, so that a list's fragments march together
// (one march's loop at a time: lavapipe's loop limit, visibility.glsl).
vec3 patch_irradiance(vec3 xi, vec3 ni, vec3 xj, vec3 nj, vec3 phi, float a) {
    vec3 v = xj - xi;
    float d2 = dot(v, v);
    vec3 dir = v * inversesqrt(max(d2, 1e-30));
    float cos_i = max(dot(ni, dir), 0.0);
    float cos_j = max(-dot(nj, dir), 0.0);
    float k = cos_i * cos_j / (PI * d2 + a);
    if (VOXEL_VISIBILITY) k *= voxel_visibility(xi, ni, xj, nj);
    return phi * k;
}

#endif
