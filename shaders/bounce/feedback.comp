#version 460
// Pass `bounce-feedback` (docs/algorithm.md section 5.9, `--bounce-feedback
// on`): instead of N - 2 propagations, one, from the power this light view's
// cells re-emitted over every bounce the frame before (`history`, S' of the
// last frame): S_i = P1_i + rho_i A_i sum_j T_ij S'_j. Over frames of a still
// scene S runs through P1, P1 + M P1, P1 + M P1 + M^2 P1, ...: the whole
// series, one bounce more a frame. S is written to the sum the receivers
// gather and kept as this view's history for the next frame. One workgroup
// for all cells: every history is read before any is written (barrier).
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 128) in;

layout(set = 1, binding = 0, std430) readonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 1, std430) readonly buffer BounceTransfer { float transfer[]; };
// In: every cell's first bounce P1 (bounce-cells); out: S.
layout(set = 1, binding = 2, std430) buffer BouncePowerSum { vec4 power_sum[]; };
// In: this view's S of the last frame (0 before its first); out: this frame's.
layout(set = 1, binding = 3, std430) buffer BounceHistory { vec4 history[]; };

const uint PER_THREAD = (uint(BOUNCE_CELLS) + 127u) / 128u;

void main() {
    uint t = gl_LocalInvocationIndex;
    vec3 sums[PER_THREAD];
    for (uint k = 0u; k < PER_THREAD; ++k) {
        uint i = t + 128u * k;
        if (i >= uint(BOUNCE_CELLS)) break;
        vec3 e = vec3(0.0);
        uint row = i * uint(BOUNCE_CELLS);
        for (uint j = 0u; j < uint(BOUNCE_CELLS); ++j) e += transfer[row + j] * history[j].rgb;
        uint c = uint(BOUNCE_CELL_VEC4S) * i;
        sums[k] = power_sum[i].rgb + cells[c + 2u].rgb * e * cells[c].w;
    }
    memoryBarrierBuffer();
    barrier();
    for (uint k = 0u; k < PER_THREAD; ++k) {
        uint i = t + 128u * k;
        if (i >= uint(BOUNCE_CELLS)) break;
        power_sum[i] = vec4(sums[k], 0.0);
        history[i] = vec4(sums[k], 0.0);
    }
}
