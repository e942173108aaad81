#version 460
// Pass `bounce-reach` (docs/algorithm.md section 5.9), after
// `bounce-transfer`: for every face, the share of the power it re-emits
// that the faces receive in all, F_a = sum_b V_ij K_ba A_b (the kernel of
// bounce-propagate, symmetric in the two faces), and the scale 1 / max(1,
// F_a) that bounce-propagate puts on the face's power. With it no face
// hands on more power than it sends, so each bounce has less power than
// the one before (at most max rho of it) and the series converges. Without
// it, faces close together in one cell of a folded surface (Sponza's
// arches and columns) each received nearly all of each other's power, and
// the series grew without end. One invocation per cell, its six faces.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 64) in;

layout(set = 1, binding = 0, std430) readonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 1, std430) readonly buffer BounceTransfer { float transfer[]; };
layout(set = 1, binding = 2, std430) writeonly buffer BounceReach { float reach[]; };

void main() {
    int j = int(gl_GlobalInvocationID.x);
    if (j >= BOUNCE_CELLS) return;
    vec4 sx[BOUNCE_FACES];
    vec3 sn[BOUNCE_FACES], f[BOUNCE_FACES];
    for (int a = 0; a < BOUNCE_FACES; ++a) {
        int s = bounce_face(j, a);
        sx[a] = cells[s];
        sn[a] = cells[s + 1].xyz;
        f[a] = vec3(0.0);
    }
    if (cells[BOUNCE_CELL_VEC4S * j].w > 0.0) {
        // One loop over every receiving face (see bounce-gather).
        for (int k = 0; k < BOUNCE_PATCHES; ++k) {
            int i = k / BOUNCE_FACES, b = k % BOUNCE_FACES;
            float v = transfer[i * BOUNCE_CELLS + j];
            if (v <= 0.0) {
                k += BOUNCE_FACES - 1 - b;
                continue;
            }
            int r = bounce_face(i, b);
            vec4 xr = cells[r];
            // The kernel is symmetric: the receiving face b takes the
            // sender's place, and its area is the "power".
            if (xr.w > 0.0) bounce_receive(f, sx, sn, i == j, b, xr, cells[r + 1].xyz, vec3(xr.w), v);
        }
    }
    for (int a = 0; a < BOUNCE_FACES; ++a) reach[BOUNCE_FACES * j + a] = 1.0 / max(1.0, f[a].x);
}
