#version 460
// Pass `bounce-feedback` (docs/algorithm.md section 5.9, `--bounce-feedback
// on`): instead of N - 2 propagations, one, from the power this light view's
// cells' faces re-emitted over every bounce the frame before (`history`, S'
// of the last frame): S_b = P1_b + rho_b A_b sum_a V_ij K_ba S'_a (the
// faces' kernels as in bounce-propagate). Over frames of a still
// scene S runs through P1, P1 + M P1, P1 + M P1 + M^2 P1, ...: the whole
// series, one bounce more a frame. S is written to the sum the receivers
// gather and kept as this view's history for the next frame. One workgroup
// for all faces: every history is read before any is written (barrier).
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 128) in;

layout(set = 1, binding = 0, std430) readonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 1, std430) readonly buffer BounceTransfer { float transfer[]; };
// In: every face's first bounce P1 (bounce-cells); out: S.
layout(set = 1, binding = 2, std430) buffer BouncePowerSum { vec4 power_sum[]; };
// In: this view's S of the last frame (0 before its first); out: this frame's.
layout(set = 1, binding = 3, std430) buffer BounceHistory { vec4 history[]; };
// Each face's scale on the power it hands on (bounce-reach).
layout(set = 1, binding = 4, std430) readonly buffer BounceReach { float reach[]; };

const int PER_THREAD = (BOUNCE_CELLS + 127) / 128;

void main() {
    int t = int(gl_LocalInvocationIndex);
    vec3 sums[PER_THREAD * BOUNCE_FACES];
    for (int m = 0; m < PER_THREAD; ++m) {
        int i = t + 128 * m;
        vec4 rx[BOUNCE_FACES];
        vec3 rn[BOUNCE_FACES], e[BOUNCE_FACES];
        for (int b = 0; b < BOUNCE_FACES; ++b) {
            int f = bounce_face(i, b);
            rx[b] = cells[f];
            rn[b] = cells[f + 1].xyz;
            e[b] = vec3(0.0);
        }
        if (cells[BOUNCE_CELL_VEC4S * i].w > 0.0) {
            // One loop over every sending face (see bounce-gather).
            for (int k = 0; k < BOUNCE_PATCHES; ++k) {
                int j = k / BOUNCE_FACES, a = k % BOUNCE_FACES;
                float v = transfer[i * BOUNCE_CELLS + j];
                if (v <= 0.0) {
                    k += BOUNCE_FACES - 1 - a;
                    continue;
                }
                int s = bounce_face(j, a);
                vec4 xs = cells[s];
                if (xs.w > 0.0) bounce_receive(e, rx, rn, i == j, a, xs, cells[s + 1].xyz, history[k].rgb * reach[k], v);
            }
        }
        for (int b = 0; b < BOUNCE_FACES; ++b) {
            int o = BOUNCE_FACES * i + b;
            sums[BOUNCE_FACES * m + b] = power_sum[o].rgb + cells[bounce_face(i, b) + 2].rgb * e[b] * rx[b].w;
        }
    }
    memoryBarrierBuffer();
    barrier();
    for (int m = 0; m < PER_THREAD; ++m) {
        for (int b = 0; b < BOUNCE_FACES; ++b) {
            int o = BOUNCE_FACES * (t + 128 * m) + b;
            power_sum[o] = vec4(sums[BOUNCE_FACES * m + b], 0.0);
            history[o] = vec4(sums[BOUNCE_FACES * m + b], 0.0);
        }
    }
}
