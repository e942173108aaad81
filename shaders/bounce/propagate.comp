#version 460
// Pass `bounce-propagate` (docs/algorithm.md section 5.9): one bounce more
// among the cells' faces, one workgroup for all of them: each face receives
// E_b = sum over sending faces a of V_ij K_ba P_a from the power every face
// re-emitted at the previous bounce (V_ij the cells' visibility from
// bounce-transfer, K_ba the patch formula between the faces as discs, P_a
// scaled by bounce-reach so that no face hands on more than it sends) and
// re-emits P_b = rho_b E_b A_b, added to its sum over bounces.
// With BOUNCE_INFINITE (`--bounces inf`) the pass stops the series once a
// bounce brings under 1% of the power summed so far: later dispatches of the
// frame find `done` set and return.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 128) in;
layout(constant_id = 81) const bool BOUNCE_INFINITE = false;

layout(set = 1, binding = 0, std430) readonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 1, std430) readonly buffer BounceTransfer { float transfer[]; };
layout(set = 1, binding = 2, std430) readonly buffer PowerIn { vec4 power_in[]; };
layout(set = 1, binding = 3, std430) writeonly buffer PowerOut { vec4 power_out[]; };
layout(set = 1, binding = 4, std430) buffer BouncePowerSum { vec4 power_sum[]; };
layout(set = 1, binding = 5, std430) buffer BounceState { uint done; };
// Each face's scale on the power it hands on (bounce-reach).
layout(set = 1, binding = 6, std430) readonly buffer BounceReach { float reach[]; };

// The share of the summed power under which a bounce ends the series.
const float BOUNCE_CONVERGED = 0.01;

shared vec2 totals[128];

void main() {
    if (done != 0u) return;
    uint t = gl_LocalInvocationIndex;
    vec2 total = vec2(0.0);  // x: this bounce's power, y: the sum's (r + g + b)
    for (int i = int(t); i < BOUNCE_CELLS; i += 128) {
        if (cells[BOUNCE_CELL_VEC4S * i].w <= 0.0) continue;
        vec4 rx[BOUNCE_FACES];
        vec3 rn[BOUNCE_FACES], e[BOUNCE_FACES];
        for (int b = 0; b < BOUNCE_FACES; ++b) {
            int f = bounce_face(i, b);
            rx[b] = cells[f];
            rn[b] = cells[f + 1].xyz;
            e[b] = vec3(0.0);
        }
        // One loop over every sending face (see bounce-gather).
        for (int k = 0; k < BOUNCE_PATCHES; ++k) {
            int j = k / BOUNCE_FACES, a = k % BOUNCE_FACES;
            float v = transfer[i * BOUNCE_CELLS + j];
            if (v <= 0.0) {
                k += BOUNCE_FACES - 1 - a;  // nothing of cell j arrives: past its faces
                continue;
            }
            int s = bounce_face(j, a);
            vec4 xs = cells[s];
            if (xs.w > 0.0) bounce_receive(e, rx, rn, i == j, a, xs, cells[s + 1].xyz, power_in[k].rgb * reach[k], v);
        }
        for (int b = 0; b < BOUNCE_FACES; ++b) {
            vec3 p = cells[bounce_face(i, b) + 2].rgb * e[b] * rx[b].w;
            int o = BOUNCE_FACES * i + b;
            power_out[o] = vec4(p, 0.0);
            vec3 sum = power_sum[o].rgb + p;
            power_sum[o] = vec4(sum, 0.0);
            total += vec2(p.r + p.g + p.b, sum.r + sum.g + sum.b);
        }
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
