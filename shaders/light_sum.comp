#version 460
// Sums the direct and indirect images over a frame's light views (spot, each
// cube face of a point light, directional; docs/algorithm.md section 2.4): every
// view's passes write `direct` and `indirect` as if it were the only light, and
// this pass adds them up in two images of its own. mode 0 (first view):
// sum = this view; 1: sum += this view; 2 (last view): this view += sum, so
// `direct` and `indirect` end as the totals the composite and readback see.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, rgba32f) uniform image2D direct;
layout(set = 1, binding = 1, rgba32f) uniform image2D indirect;
layout(set = 1, binding = 2, rgba32f) uniform image2D direct_sum;
layout(set = 1, binding = 3, rgba32f) uniform image2D indirect_sum;

layout(push_constant) uniform Push { int mode; };

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, ivec2(run.output_size)))) return;
    vec4 d = imageLoad(direct, p);
    vec4 i = imageLoad(indirect, p);
    if (mode == 0) {
        imageStore(direct_sum, p, d);
        imageStore(indirect_sum, p, i);
    } else if (mode == 1) {
        imageStore(direct_sum, p, imageLoad(direct_sum, p) + d);
        imageStore(indirect_sum, p, imageLoad(indirect_sum, p) + i);
    } else {
        // Alpha marks geometry (direct) and patches (indirect): the same in
        // every view, so it is kept rather than summed.
        imageStore(direct, p, vec4(d.rgb + imageLoad(direct_sum, p).rgb, d.a));
        imageStore(indirect, p, vec4(i.rgb + imageLoad(indirect_sum, p).rgb, i.a));
    }
}
