// What the voxel grid holds of the surface inside each finest cell
// (docs/algorithm.md section 5.8), the layout shared by the pass that
// writes it (voxel_grid/surface.frag) and every pass that reads it; the host
// mirrors it in src/voxel_grid/surface.rs (tests/layouts.rs holds the two
// together). Per cell, SURFACE_WORDS words of fixed-point sums over the
// surface inside it, each in units of a cell face's area / SURFACE_ONE
// (integer atomics: the sums do not depend on the order fragments arrive
// in, so the grid is the same every run):
//   0      A: the area
//   1-3    rho A: albedo times area (linear RGB)
//   4-6    n A: the front face's unit normal times area (signed)
//   7-9    f A: the offset inside the cell (0..1 per axis) times area
//   10-11  unused
#ifndef SURFACE_GLSL
#define SURFACE_GLSL

const uint SURFACE_WORDS = 12u;
const float SURFACE_ONE = 65536.0;

#endif
