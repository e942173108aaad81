#version 460
// The upsampling's push into level 0 (docs/algorithm.md section 3, step 7):
// every pixel with geometry takes its level-0 patch value, or else the value
// pushed from level 1's taps (push_value in multires/upsample.glsl); background is 0.
// A full-screen draw into `indirect` rather than a compute dispatch: CPU
// drivers write color attachments a tile at a time, which costs less than a
// storage-image store per pixel.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"

layout(set = 1, binding = 0, rgba32f) readonly uniform image2DArray illumination;
layout(set = 1, binding = 1, rgba32f) readonly uniform image2DArray taps;

layout(constant_id = 12) const bool INTERPOLATE = true;

#include "multires/upsample.glsl"

layout(location = 0) out vec4 out_irradiance;  // rgb: E (W/m^2)

// A pixel with geometry is a level-0 patch, which holds its value, or else
// its parent does not split (a split parent makes it a patch), so the parent
// is smooth and fully covered (docs/algorithm.md section 3, steps 3-4). The
// pixels that need a push are therefore those without a value whose parent
// is fully covered, and the G-buffer need not be read.
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 v = imageLoad(illumination, ivec3(p, 0));
    vec4 pushed = push_value(p, 0);
    bool push = v.a <= 0.0 && (uint(pushed.a) & TAP_FULL) != 0u;
    out_irradiance = vec4(v.a > 0.0 ? v.rgb : push ? pushed.rgb : vec3(0.0), 1.0);
}
