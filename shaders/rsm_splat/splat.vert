#version 460
// Methods rsm-splat and rsm-splat-restricted (docs/algorithm.md section 5): VPL j
// (the instance) draws one quad; its fragments add that VPL's irradiance.
// Full screen, or (RESTRICTED) the screen rectangle of the sphere where the
// VPL's contribution can exceed SPLAT_THRESHOLD: with both cosines at most 1 and
// A_j >= 0, E <= Phi_max / (pi d^2), so beyond d = sqrt(Phi_max / (pi t)) it
// is below t. Empty VPLs draw nothing.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(constant_id = 50) const bool RESTRICTED = false;
// The irradiance bound (W/m^2) past which a restricted splat ends
// (methods::rsm_splat, --splat-threshold).
layout(constant_id = 51) const float SPLAT_THRESHOLD = 0.0;

layout(set = 1, binding = 2) uniform sampler2D rsm_position;
layout(set = 1, binding = 3) uniform sampler2D rsm_normal;
layout(set = 1, binding = 4) uniform sampler2D rsm_flux;
#include "regular_vpls/regular_vpls.glsl"

layout(location = 0) flat out vec4 out_position;  // xyz: x_j; w: A_j
layout(location = 1) flat out vec4 out_normal;  // w: patch_level
layout(location = 2) flat out vec3 out_flux;

// The NDC rectangle covering the sphere (centre c, radius r); the whole
// screen when the sphere reaches behind the camera.
vec4 screen_bounds(vec3 c, float r) {
    vec2 lo = vec2(1.0), hi = vec2(-1.0);
    for (int i = 0; i < 8; ++i) {
        vec3 corner = c + r * vec3((i & 1) != 0 ? 1.0 : -1.0, (i & 2) != 0 ? 1.0 : -1.0, (i & 4) != 0 ? 1.0 : -1.0);
        vec4 clip = u.camera_view_proj * vec4(corner, 1.0);
        if (clip.w <= 1e-6) return vec4(-1.0, -1.0, 1.0, 1.0);
        vec2 ndc = clip.xy / clip.w;
        lo = min(lo, ndc);
        hi = max(hi, ndc);
    }
    return vec4(clamp(lo, vec2(-1.0), vec2(1.0)), clamp(hi, vec2(-1.0), vec2(1.0)));
}

void main() {
    vec4 pos, nrm;
    vec3 flux;
    bool live = regular_vpl(gl_InstanceIndex, pos, nrm, flux);
    vec4 rect = vec4(-1.0, -1.0, 1.0, 1.0);
    if (live && RESTRICTED && SPLAT_THRESHOLD > 0.0) {
        float radius = sqrt(max(flux.r, max(flux.g, flux.b)) / (PI * SPLAT_THRESHOLD));
        rect = screen_bounds(pos.xyz, radius);
    }
    const vec2 quad[6] = vec2[6](vec2(0, 0), vec2(1, 0), vec2(0, 1), vec2(1, 0), vec2(1, 1), vec2(0, 1));
    vec2 q = quad[gl_VertexIndex];
    // A degenerate quad (all vertices at one point) rasterizes nothing.
    gl_Position = live ? vec4(mix(rect.xy, rect.zw, q), 0.0, 1.0) : vec4(2.0, 2.0, 0.0, 1.0);
    out_position = pos;
    out_normal = nrm;
    out_flux = flux;
}
