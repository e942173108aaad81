#version 460
// One VPL's irradiance at one patch of the multiresolution buffer (its mean
// position and normal), added by the blend state (color ONE + ONE, alpha MAX,
// so alpha = 1 marks the patches as the gather does). See multires_splat/splat.vert.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "vpl.glsl"

layout(early_fragment_tests) in;

layout(set = 1, binding = 0) uniform sampler2D geo_mean;    // levels 1..L (multires/geo_levels.glsl)
layout(set = 1, binding = 1) uniform sampler2D geo_normal;  // levels 1..L
layout(set = 1, binding = 5) uniform sampler2D gbuffer_position;  // level 0
layout(set = 1, binding = 6) uniform sampler2D gbuffer_normal;
#include "multires/geo_levels.glsl"

layout(location = 0) flat in int level;
layout(location = 1) flat in vec4 in_position;
layout(location = 2) flat in vec4 in_normal;  // w: patch_level
layout(location = 3) flat in vec3 in_flux;

layout(location = 0) out vec4 out_irradiance;
layout(location = 1) out float out_evaluations;  // one per splat

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 xi = geo_mean_at(p, level).xyz;
    vec3 ni = geo_normal_at(p, level).xyz;
    out_irradiance = vec4(patch_irradiance(xi, ni, in_position.xyz, in_normal.xyz, in_flux, in_position.w, int(in_normal.w)), 1.0);
    out_evaluations = 1.0;
}
