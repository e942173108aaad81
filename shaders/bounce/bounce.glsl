// Multiple bounces through the voxel grid's cells (docs/algorithm.md
// section 5.9, "Multiple bounces"): the layout shared by the passes of
// src/bounce/. The grid's finest cells are merged into BOUNCE_SIDE^3 coarse
// cells, each a piece of surface that receives light and re-emits it: its
// power rho E A (W) is what it sends on (shared notes, section 11).
#ifndef BOUNCE_GLSL
#define BOUNCE_GLSL

// Coarse cells per side of the grid's cube, and in all (src/bounce/mod.rs
// mirrors both): few enough that every cell sees every other in one frame
// (BOUNCE_CELLS^2 pairs), and that a receiver's loop over them stays far
// under lavapipe's 65,535 iterations with a march per cell.
const int BOUNCE_SIDE = 8;
const int BOUNCE_CELLS = BOUNCE_SIDE * BOUNCE_SIDE * BOUNCE_SIDE;

// Each cell is three vec4s in `cells`:
//   [0] xyz: the centroid of its surface (world), w: its area (m^2; 0: empty)
//   [1] xyz: the unit mean normal, w: the mean normal's length (1 flat, less
//       where the surface inside bends or folds)
//   [2] rgb: the area-weighted mean albedo
const int BOUNCE_CELL_VEC4S = 3;

// Receivers: one per BOUNCE_STEP x BOUNCE_STEP pixels (bounce::STEP).
layout(constant_id = 80) const int BOUNCE_STEP = 4;

#endif
