// Multiple bounces through the voxel grid's cells (docs/algorithm.md
// section 5.9, "Multiple bounces"): the layout shared by the passes of
// src/bounce/. The grid's finest cells are merged into BOUNCE_SIDE^3 coarse
// cells, each a piece of surface that receives light and re-emits it: its
// power rho E A (W) is what it sends on (shared notes, section 11).
#ifndef BOUNCE_GLSL
#define BOUNCE_GLSL

// Coarse cells per side of the grid's cube, and in all (src/bounce/mod.rs
// mirrors both): few enough that every cell sees every other in one frame
// (BOUNCE_CELLS^2 pairs), and that a receiver's loop over their faces stays
// under lavapipe's 65,535 iterations with a march per face.
const int BOUNCE_SIDE = 8;
const int BOUNCE_CELLS = BOUNCE_SIDE * BOUNCE_SIDE * BOUNCE_SIDE;

// A cell's surface is split by facing into BOUNCE_FACES faces (+x, -x, +y,
// -y, +z, -z): each finest cell's area goes to the faces its mean normal m
// points to, m_k^2 of it to the face of axis k and m's sign, and the rest,
// 1 - |m|^2 (surfaces that fold inside the finest cell), evenly to all six.
// A face is a piece of surface of its own, with its centroid, mean normal,
// albedo, first bounce and power: a floor and the pillar standing on it, or
// the two walls of a corner, share a cell but not a face.
const int BOUNCE_FACES = 6;
const int BOUNCE_PATCHES = BOUNCE_CELLS * BOUNCE_FACES;

// Each cell is BOUNCE_CELL_VEC4S vec4s in `cells`:
//   [0] xyz: the centroid of all its surface (world), w: its area (m^2; 0: empty)
//   then per face f, at 1 + 3 f (bounce_face):
//   [0] xyz: the face's centroid, w: its area (m^2; 0: empty)
//   [1] xyz: its unit mean normal
//   [2] rgb: its area-weighted mean albedo
// Powers (`power`, `power_sum`) are one vec4 per face, at BOUNCE_FACES c + f.
const int BOUNCE_CELL_VEC4S = 1 + 3 * BOUNCE_FACES;

// The index in `cells` of face f of cell c.
int bounce_face(int c, int f) { return BOUNCE_CELL_VEC4S * c + 1 + 3 * f; }

// Receivers: one per BOUNCE_STEP x BOUNCE_STEP pixels (bounce::STEP).
layout(constant_id = 80) const int BOUNCE_STEP = 4;

#ifdef VPL_GLSL
// Adds to e[b] the irradiance each face b of a receiving cell (rx: centroid
// and area, rn: unit normal; area 0: no face) gets from a sending face
// (xs: centroid and area, ns: normal) re-emitting the power p, with v the
// two cells' visibility (bounce-transfer): the patch formula between faces
// as discs, with the larger face's area in the kernel's denominator,
// cos cos / (pi d^2 + max(A_r, A_s)), so that the share of either face's
// power the other receives, K A, is at most 1 both ways (with the sender's
// area alone, a large face beside a small one in a cell that folds received
// A_r / A_s times the small face's power, and the series grew bounce after
// bounce). `same`: the sender is face a of the receiving cell, which does
// not light itself. The six receiving faces are unrolled by hand: a loop
// would count toward lavapipe's 65,535 iterations in the caller's loop over
// every sending face.
void bounce_receive(inout vec3 e[BOUNCE_FACES], vec4 rx[BOUNCE_FACES], vec3 rn[BOUNCE_FACES],
                    bool same, int a, vec4 xs, vec3 ns, vec3 p, float v) {
#define BOUNCE_RECEIVE_FACE(b)                                                       \
    if (rx[b].w > 0.0 && !(same && a / 2 == b / 2))                                       \
        e[b] += v * patch_unshadowed(rx[b].xyz, rn[b], xs.xyz, ns, p, max(xs.w, rx[b].w), 0);
    BOUNCE_RECEIVE_FACE(0) BOUNCE_RECEIVE_FACE(1) BOUNCE_RECEIVE_FACE(2)
    BOUNCE_RECEIVE_FACE(3) BOUNCE_RECEIVE_FACE(4) BOUNCE_RECEIVE_FACE(5)
#undef BOUNCE_RECEIVE_FACE
}
#endif

#endif
