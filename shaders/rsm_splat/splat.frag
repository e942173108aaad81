#version 460
// One VPL's irradiance at this pixel, added into the target by the blend
// state (ONE + ONE). See rsm_splat/splat.vert.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;

layout(location = 0) flat in vec4 in_position;
layout(location = 1) flat in vec4 in_normal;  // w: patch_level
layout(location = 2) flat in vec3 in_flux;

layout(location = 0) out vec4 out_irradiance;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(gbuffer_position, pixel, 0);
    vec3 e = vec3(0.0);
    if (p.w > 0.0) {
        vec3 n = normalize(texelFetch(gbuffer_normal, pixel, 0).xyz);
        e = patch_irradiance(p.xyz, n, in_position.xyz, in_normal.xyz, in_flux, in_position.w, int(in_normal.w));
    }
    out_irradiance = vec4(e, 0.0);
}
