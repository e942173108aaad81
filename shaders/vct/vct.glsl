// Method vct (voxel cone tracing, Crassin et al. 2011; docs/algorithm.md
// section 9): what every VCT shader shares. The cells are the voxel grid's
// finest cells (its cube in the frame uniforms, u.grid_cube: min corner and
// a cell's side h).
//
// The injection sums, ACCUM_WORDS words per cell (integer atomics: the same
// sums in any order; mirrored in src/methods/vct/volume.rs):
//   0-2  Phi: the flux of the RSM texels inside the cell (RGB), in units of
//        vct_flux_unit() W
//   3    A_rsm: their area, in cell faces / AREA_ONE
//   4-6  n Phi: their normals times their flux's mean over RGB (signed, same
//        units as Phi)
//   7    unused
//
// Specialisation constants (every VCT pipeline sets them; src/methods/vct/
// is their one writer):
//   80 VCT_SIZE  cells per side of the finest level
#ifndef VCT_GLSL
#define VCT_GLSL

layout(constant_id = 90) const int VCT_SIZE = 64;

const uint ACCUM_WORDS = 8u;
const float AREA_ONE = 4096.0;

// The flux one integer unit stands for: every texel's flux is at most
// rho I dw <= I_peak t^2 (t the texel's side on the unit image plane,
// dw <= t^2; a directional light's texel of side t metres carries at most
// E t^2), so R^2 texels sum to at most 2^31 units: no word overflows,
// whatever the scene, and a texel's flux is resolved to 2^-31 R^2 of the
// largest possible (1 / 32768 at R = 256).
float vct_flux_unit() {
    float r = float(run.rsm_resolution);
    float t = 2.0 * u.rsm_half_extent / r;
    return max(u.light_peak, 1e-30) * t * t * r * r / 2147483648.0;
}

int vct_cell_index(ivec3 c) {
    return (c.z * VCT_SIZE + c.y) * VCT_SIZE + c.x;
}

#endif
