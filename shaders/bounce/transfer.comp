#version 460
// Pass `bounce-transfer` (docs/algorithm.md section 5.9): one invocation per
// pair of coarse cells (i receives, j sends): the irradiance at cell i's
// centroid per watt that cell j re-emits, the patch formula with the
// methods' visibility (vpl.glsl), kept for every later bounce of the frame.
// A cell does not light itself (its own surface lies in its plane, or
// nearly).
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, std430) readonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 1, std430) writeonly buffer BounceTransfer { float transfer[]; };

void main() {
    uint i = gl_GlobalInvocationID.x, j = gl_GlobalInvocationID.y;
    if (i >= uint(BOUNCE_CELLS) || j >= uint(BOUNCE_CELLS)) return;
    uint ci = uint(BOUNCE_CELL_VEC4S) * i, cj = uint(BOUNCE_CELL_VEC4S) * j;
    vec4 xi = cells[ci], xj = cells[cj];
    float k = 0.0;
    if (i != j && xi.w > 0.0 && xj.w > 0.0) {
        k = patch_irradiance(xi.xyz, cells[ci + 1u].xyz, xj.xyz, cells[cj + 1u].xyz, vec3(1.0), xj.w, 0).x;
    }
    transfer[i * uint(BOUNCE_CELLS) + j] = k;
}
