#version 460
#extension GL_GOOGLE_include_directive : require
// Final radiance (docs/algorithm.md section 2): direct + rho/pi * E_indirect.
// Indirect irradiance is multiplied by the full-resolution albedo here, so
// coarse illumination patches never blur textures.
#include "frame.glsl"
#include "lighting.glsl"

layout(set = 1, binding = 0) uniform sampler2D direct_radiance;
layout(set = 1, binding = 1) uniform sampler2D gbuffer_albedo;
layout(set = 1, binding = 2) uniform sampler2D indirect_irradiance;

layout(location = 0) out vec4 out_radiance;  // rgb: W/(m^2 sr)

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec3 direct = texelFetch(direct_radiance, pixel, 0).rgb;
    vec3 albedo = texelFetch(gbuffer_albedo, pixel, 0).rgb;
    vec3 irradiance = texelFetch(indirect_irradiance, pixel, 0).rgb;
    out_radiance = vec4(direct + albedo / PI * irradiance, 1.0);
}
