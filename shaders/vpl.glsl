// Light patches and their contribution to a receiver (docs/algorithm.md section 2).
#ifndef VPL_GLSL
#define VPL_GLSL

// C_{j->i} / rho_i: the irradiance a patch with flux phi (W), world area a
// (m^2), position xj and unit normal nj gives a receiver at xi with unit normal
// ni, with the disc form factor that stays finite as the distance goes to 0:
//   E = phi * cos_i * cos_j / (pi * d^2 + A_j)
vec3 patch_irradiance(vec3 xi, vec3 ni, vec3 xj, vec3 nj, vec3 phi, float a) {
    vec3 v = xj - xi;
    float d2 = dot(v, v);
    vec3 dir = v * inversesqrt(max(d2, 1e-30));
    float cos_i = max(dot(ni, dir), 0.0);
    float cos_j = max(-dot(nj, dir), 0.0);
    return phi * (cos_i * cos_j / (PI * d2 + a));
}

#endif
