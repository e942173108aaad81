#version 460
// Level 1 of the geometry mipmaps from the G-buffer (multires/geometry_mips.glsl).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;  // xyz world, w view depth (0: background)
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;    // xyz: unit normal; w: view depth, scaled (16-bit)

#define GEO_LEVEL0_ONLY
#include "multires/geo_levels.glsl"
#include "multires/geometry_mips.glsl"

// Level 1 from the G-buffer's 4x4 pixels around texel p (its 2x2 children
// and their one-pixel ring): the children's sums and the ranges over the
// pixels with geometry. The ranges take the view depth from the normal's w
// (16 bits, relative error under 0.05%; scaled by a power of two fitted to
// the scene so that no depth it holds overflows or underflows, which the
// ranges' ratios do not see), so the ring costs one fetch per
// pixel; the means take it from the position (32 bits). Each pixel is fetched
// unconditionally (clamped, then masked): fetches under a condition cost CPU
// drivers as much as taken ones.
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 size = ivec2(run.output_size);
    vec4 mean = vec4(0.0);
    vec3 normal = vec3(0.0);
    float coverage = 0.0;
    vec4 lo = vec4(BIG), hi = vec4(-BIG);
    [[unroll]] for (int dy = -1; dy <= 2; ++dy) {
        [[unroll]] for (int dx = -1; dx <= 2; ++dx) {
            ivec2 q = 2 * p + ivec2(dx, dy);
            bool inside = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size));
            ivec2 qc = clamp(q, ivec2(0), size - 1);
            vec4 qn = texelFetch(gbuffer_normal, qc, 0);
            if (inside && qn.w > 0.0) {
                lo = min(lo, qn.wxyz);
                hi = max(hi, qn.wxyz);
            }
            // The children (always inside: qc = q), in the order of the
            // levels above.
            if (dx >= 0 && dx <= 1 && dy >= 0 && dy <= 1) {
                vec4 cn = level0_normal(qc);
                mean += cn.w * level0_mean(qc);
                normal += cn.w * cn.xyz;
                coverage += cn.w;
            }
        }
    }
    write_texel(mean, normal, coverage, lo, hi, false);
}
