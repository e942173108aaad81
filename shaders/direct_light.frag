#version 460
#extension GL_GOOGLE_include_directive : require
// Direct light of one light view (docs/algorithm.md sections 2.3 and 2.4):
//   L_direct = rho/pi * I(w) * max(0, n.l) / r^2 * V   (spot; point, this cube face's points)
//   L_direct = rho/pi * E * max(0, n.l) * V            (directional)
// with V from the RSM depth: 3x3 taps of hardware 2x2 PCF. Several views add up
// (renderer: light_sum.comp).
#include "frame.glsl"
#include "light_types.glsl"

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 1, binding = 2) uniform sampler2D gbuffer_albedo;
layout(set = 1, binding = 3) uniform sampler2DShadow rsm_depth;  // compare: GREATER_OR_EQUAL

layout(location = 0) out vec4 out_radiance;  // rgb: W/(m^2 sr)

float visibility(vec3 p, vec3 n, float cos_i) {
    float res = float(run.rsm_resolution);
    // One RSM texel spans this many metres at the receiver's depth.
    float texel_world = shadow_texel_world(p);
    vec4 clip = u.light_view_proj * vec4(p + n * (run.shadow_normal_offset * texel_world), 1.0);
    if (clip.w <= 0.0) return 0.0;
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = ndc.xy * 0.5 + 0.5;
    // Reversed-Z depth: larger is closer to the light. The receiver is lit when
    // it is at least as close as the stored occluder. Within one texel (and
    // across the PCF footprint) a surface tilted by theta from the light
    // changes depth by texel * tan(theta): bias by that many texels
    // (shadow_reference in light_types.glsl).
    float tan_theta = min(sqrt(max(1.0 - cos_i * cos_i, 0.0)) / max(cos_i, 1e-3), 20.0);
    float ref = shadow_reference(ndc.z, tan_theta, texel_world);
    float radius = run.pcf_radius;
    float sum = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            sum += texture(rsm_depth, vec3(uv + vec2(x, y) * (radius / res), ref));
    return sum / 9.0;
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 position = texelFetch(gbuffer_position, pixel, 0);
    if (position.w <= 0.0) {
        out_radiance = vec4(0.0);
        return;
    }
    vec3 p = position.xyz;
    vec3 n = texelFetch(gbuffer_normal, pixel, 0).xyz;
    vec3 albedo = texelFetch(gbuffer_albedo, pixel, 0).rgb;
    float r2;
    vec3 l = light_direction_from(p, r2);
    float cos_i = max(dot(n, l), 0.0);
    vec3 radiance = albedo / PI * light_intensity_toward(p, u.cube_face) * cos_i / r2;
    if (cos_i > 0.0) radiance *= visibility(p, n, cos_i);
    out_radiance = vec4(radiance, 1.0);
}
