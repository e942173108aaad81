#version 460
// Pass `bounce-gather` (docs/algorithm.md section 5.9): receivers at one
// pixel of each BOUNCE_STEP x BOUNCE_STEP block (its centre) gather bounces
// 2..N from every cell face's power summed over bounces 1..N-1, the patch
// formula with the face's mean normal (a wall is not lit from behind) and
// the methods' visibility, the face a disc like a patch. Writes one
// irradiance per block.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 1, binding = 2, std430) readonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 3, std430) readonly buffer BouncePowerSum { vec4 power_sum[]; };
layout(set = 1, binding = 4, std430) writeonly buffer BounceReceived { vec4 received[]; };

// Cells staged in shared memory STAGED at a time: every receiver of the
// workgroup reads every face, and lavapipe reads storage per lane, slowly.
const int STAGED = 8;
const int STAGED_VEC4S = STAGED * BOUNCE_CELL_VEC4S;
shared vec4 staged[STAGED_VEC4S];
shared vec4 staged_power[STAGED * BOUNCE_FACES];

void main() {
    ivec2 size = ivec2(run.output_size);
    ivec2 low = (size + BOUNCE_STEP - 1) / BOUNCE_STEP;
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    int t = int(gl_LocalInvocationIndex);
    bool inside = all(lessThan(q, low));
    ivec2 pixel = min(q * BOUNCE_STEP + BOUNCE_STEP / 2, size - 1);
    vec4 p = inside ? texelFetch(gbuffer_position, pixel, 0) : vec4(0.0);
    vec3 n = normalize(texelFetch(gbuffer_normal, pixel, 0).xyz);
    vec3 e = vec3(0.0);
    // One loop over every face (the cell's and face's indices from one
    // counter): a loop per cell and one per face inside it would count
    // both toward lavapipe's 65,535 iterations.
    for (int c0 = 0; c0 < BOUNCE_CELLS; c0 += STAGED) {
        barrier();
        for (int k = t; k < STAGED_VEC4S; k += 64) staged[k] = cells[BOUNCE_CELL_VEC4S * c0 + k];
        for (int k = t; k < STAGED * BOUNCE_FACES; k += 64) staged_power[k] = power_sum[BOUNCE_FACES * c0 + k];
        barrier();
        if (p.w <= 0.0) continue;
        for (int k = 0; k < STAGED * BOUNCE_FACES; ++k) {
            int j = k / BOUNCE_FACES;
            if (staged[BOUNCE_CELL_VEC4S * j].w <= 0.0) {
                k += BOUNCE_FACES - 1;  // the cell is empty: past its faces
                continue;
            }
            int i = BOUNCE_CELL_VEC4S * j + 1 + 3 * (k % BOUNCE_FACES);
            vec4 f = staged[i];
            if (f.w <= 0.0) continue;
            vec3 nf = staged[i + 1].xyz;
            vec3 c = patch_unshadowed(p.xyz, n, f.xyz, nf, staged_power[k].rgb, f.w, 0);
            // Marched only where the face lights the receiver at all: most
            // faces of a room are behind a receiver or face away from it.
            if (VOXEL_VISIBILITY && c != vec3(0.0)) c *= voxel_visibility(p.xyz, n, f.xyz, nf, f.w);
            e += c;
        }
    }
    if (inside) received[q.x + low.x * q.y] = vec4(e, 0.0);
}
