#version 460
#extension GL_GOOGLE_include_directive : require
// Direct light of one light view (docs/algorithm.md sections 2.3 and 2.4):
//   L_direct = rho/pi * I(w) * max(0, n.l) / r^2 * V   (spot; point, this cube face's points)
//   L_direct = rho/pi * E * max(0, n.l) * V            (directional)
// with V from the shadow map (pass `shadow`: depth only, S x S, the light view's
// shadow frustum u.shadow_view_proj): 3x3 taps of hardware 2x2 PCF. Several
// views add up (renderer: light_sum.comp).
#include "frame.glsl"
#include "light_types.glsl"

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 1, binding = 2) uniform sampler2D gbuffer_albedo;
layout(set = 1, binding = 3) uniform sampler2DShadow shadow_depth;  // compare: GREATER_OR_EQUAL

layout(location = 0) out vec4 out_radiance;  // rgb: W/(m^2 sr)

// The receiver's plane in the shadow map's normalized device coordinates: NDC
// depth is an affine function of NDC xy over any plane (a projective map
// keeps planes planar, perspective or orthographic), z = ndc.z + dot(g, d).
// From two points one texel off p along the plane, projected.
vec2 receiver_gradient(vec3 p, vec3 n, vec3 ndc, float texel_world) {
    vec3 t1 = normalize(abs(n.x) < 0.9 ? cross(n, vec3(1.0, 0.0, 0.0)) : cross(n, vec3(0.0, 1.0, 0.0)));
    vec3 t2 = cross(n, t1);
    vec4 c1 = u.shadow_view_proj * vec4(p + t1 * texel_world, 1.0);
    vec4 c2 = u.shadow_view_proj * vec4(p + t2 * texel_world, 1.0);
    vec3 a = c1.xyz / c1.w - ndc;
    vec3 b = c2.xyz / c2.w - ndc;
    float det = a.x * b.y - a.y * b.x;
    // Edge-on to the light (no extent in NDC xy): no usable plane.
    if (!(abs(det) > 1e-12 * (dot(a.xy, a.xy) + dot(b.xy, b.xy)))) return vec2(0.0);
    return vec2(a.z * b.y - b.z * a.y, b.z * a.x - a.z * b.x) / det;
}

float visibility(vec3 p, vec3 n) {
    float res = float(run.shadow_resolution);
    // One shadow-map texel spans this many metres at the receiver's depth.
    float texel_world = shadow_texel_world(p);
    vec3 q = p + n * (run.shadow_normal_offset * texel_world);
    vec4 clip = u.shadow_view_proj * vec4(q, 1.0);
    if (clip.w <= 0.0) return 0.0;
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = ndc.xy * 0.5 + 0.5;
    // Reversed-Z depth: larger is closer to the light. The receiver is lit when
    // it is at least as close as the stored occluder. Each PCF tap compares
    // against the receiver's own plane at the tap (receiver-plane depth
    // bias): no normal offset is needed against acne on slopes, so shadows
    // are not shifted sideways (a normal offset of 1.5 texels moved a low
    // sun's shadow edges 3.5 texels across the floor, issue 26). What is
    // left to bias is the hardware 2x2 compare, whose texels lie up to a
    // texel from the tap on the plane: shadow_slope_bias texels of the
    // plane's gradient, and a constant (shadow_reference).
    vec2 g = receiver_gradient(q, n, ndc, max(texel_world, 1e-30));
    float texel_ndc = 2.0 / res;
    float slope = run.shadow_slope_bias * (abs(g.x) + abs(g.y)) * texel_ndc;
    float radius = run.pcf_radius;
    float sum = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
            vec2 d = vec2(x, y) * (radius / res);
            float z = ndc.z + dot(g, 2.0 * d);
            sum += texture(shadow_depth, vec3(uv + d, shadow_reference(z, slope)));
        }
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
    if (cos_i > 0.0) radiance *= visibility(p, n);
    out_radiance = vec4(radiance, 1.0);
}
