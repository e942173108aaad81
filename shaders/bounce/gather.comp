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

void main() {
    ivec2 size = ivec2(run.output_size);
    ivec2 low = (size + BOUNCE_STEP - 1) / BOUNCE_STEP;
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(q, low))) return;
    ivec2 pixel = min(q * BOUNCE_STEP + BOUNCE_STEP / 2, size - 1);
    vec4 p = texelFetch(gbuffer_position, pixel, 0);
    vec3 e = vec3(0.0);
    if (p.w > 0.0) {
        vec3 n = normalize(texelFetch(gbuffer_normal, pixel, 0).xyz);
        // One loop over every face (the cell's and face's indices from one
        // counter): a loop per cell and one per face inside it would count
        // both toward lavapipe's 65,535 iterations.
        for (int k = 0; k < BOUNCE_PATCHES; ++k) {
            int j = k / BOUNCE_FACES;
            if (cells[BOUNCE_CELL_VEC4S * j].w <= 0.0) {
                k += BOUNCE_FACES - 1 - k % BOUNCE_FACES;  // the cell is empty: past its faces
                continue;
            }
            int i = bounce_face(j, k % BOUNCE_FACES);
            vec4 f = cells[i];
            if (f.w > 0.0) e += patch_irradiance(p.xyz, n, f.xyz, cells[i + 1].xyz, power_sum[k].rgb, f.w, 0);
        }
    }
    received[q.x + low.x * q.y] = vec4(e, 0.0);
}
