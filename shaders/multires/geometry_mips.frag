#version 460
// Level l >= 2 of the geometry mipmaps from level l - 1 (multires/geometry_mips.glsl).
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

// Level l - 1 (storage views of one mip each, written by the previous draw).
layout(set = 1, binding = 0, rgba32f) readonly uniform image2D src_mean;    // xyz: mean position; w: mean view depth
layout(set = 1, binding = 1, rgba32f) readonly uniform image2D src_normal;  // xyz: mean normal (unit); w: coverage
layout(set = 1, binding = 2, rgba32f) readonly uniform image2D src_min;     // x: min depth; yzw: min normal components
layout(set = 1, binding = 3, rgba32f) readonly uniform image2D src_max;     // x: max depth; yzw: max normal components
layout(set = 1, binding = 4, r32ui) readonly uniform uimage2D src_flags;

#include "multires/geometry_mips.glsl"

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 mean = vec4(0.0);
    vec3 normal = vec3(0.0);
    float coverage = 0.0;
    vec4 lo = vec4(BIG), hi = vec4(-BIG);
    for (int i = 0; i < 4; ++i) {
        ivec2 c = 2 * p + ivec2(i & 1, i >> 1);
        vec4 cn = imageLoad(src_normal, c);
        mean += cn.w * imageLoad(src_mean, c);
        normal += cn.w * cn.xyz;
        coverage += cn.w;
        lo = min(lo, imageLoad(src_min, c));
        hi = max(hi, imageLoad(src_max, c));
    }
    // 2:1 balance (needed only where the texel would not split anyway).
    bool split = false;
    ivec2 below = imageSize(src_flags);
    for (int dy = -1; dy <= 2 && !split; ++dy) {
        for (int dx = -1; dx <= 2; ++dx) {
            ivec2 q = 2 * p + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, below))) continue;
            if ((imageLoad(src_flags, q).r & GEO_SPLIT) != 0u) {
                split = true;
                break;
            }
        }
    }
    write_texel(mean, normal, coverage, lo, hi, split);
}
