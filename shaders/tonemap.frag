#version 460
#extension GL_GOOGLE_include_directive : require
// Display encoding for the PNG: exposure, clamp, sRGB transfer function.
// The EXR keeps linear radiance; this pass exists only for viewing.
#include "frame.glsl"

layout(set = 1, binding = 0) uniform sampler2D final_radiance;

layout(location = 0) out vec4 out_color;  // sRGB-encoded, stored in a UNORM target

vec3 srgb_encode(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

void main() {
    vec3 c = texelFetch(final_radiance, ivec2(gl_FragCoord.xy), 0).rgb * run.exposure;
    out_color = vec4(srgb_encode(c), 1.0);
}
