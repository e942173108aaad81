#version 460
// Pass `bounce-propagate` (docs/algorithm.md section 5.9): one bounce more
// among the coarse cells, one workgroup for all of them: each cell receives
// E_i = sum_j T_ij P_j from the power every cell re-emitted at the previous
// bounce and re-emits P_i = rho_i E_i A_i, added to its sum over bounces.
// With BOUNCE_INFINITE (`--bounces inf`) the pass stops the series once a
// bounce brings under 1% of the power summed so far: later dispatches of the
// frame find `done` set and return.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 128) in;
layout(constant_id = 81) const bool BOUNCE_INFINITE = false;

layout(set = 1, binding = 0, std430) readonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 1, std430) readonly buffer BounceTransfer { float transfer[]; };
layout(set = 1, binding = 2, std430) readonly buffer PowerIn { vec4 power_in[]; };
layout(set = 1, binding = 3, std430) writeonly buffer PowerOut { vec4 power_out[]; };
layout(set = 1, binding = 4, std430) buffer BouncePowerSum { vec4 power_sum[]; };
layout(set = 1, binding = 5, std430) buffer BounceState { uint done; };

// The share of the summed power under which a bounce ends the series.
const float BOUNCE_CONVERGED = 0.01;

shared vec2 totals[128];

void main() {
    if (done != 0u) return;
    uint t = gl_LocalInvocationIndex;
    vec2 total = vec2(0.0);  // x: this bounce's power, y: the sum's (r + g + b)
    for (uint i = t; i < uint(BOUNCE_CELLS); i += 128u) {
        vec3 e = vec3(0.0);
        uint row = i * uint(BOUNCE_CELLS);
        for (uint j = 0u; j < uint(BOUNCE_CELLS); ++j) e += transfer[row + j] * power_in[j].rgb;
        uint c = uint(BOUNCE_CELL_VEC4S) * i;
        vec3 p = cells[c + 2u].rgb * e * cells[c].w;
        power_out[i] = vec4(p, 0.0);
        vec3 sum = power_sum[i].rgb + p;
        power_sum[i] = vec4(sum, 0.0);
        total += vec2(p.r + p.g + p.b, sum.r + sum.g + sum.b);
    }
    if (!BOUNCE_INFINITE) return;
    totals[t] = total;
    for (uint stride = 64u; stride > 0u; stride >>= 1u) {
        barrier();
        if (t < stride) totals[t] += totals[t + stride];
    }
    barrier();
    if (t == 0u && totals[0].x <= BOUNCE_CONVERGED * totals[0].y) done = 1u;
}
