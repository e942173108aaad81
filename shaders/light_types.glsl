// What differs between the light types (docs/algorithm.md section 2.4): spot,
// one cube face of a point light, directional. Every pass that depends on the
// type calls these small functions, so a pass's own code stays the same for
// all types. Needs frame.glsl (`u`, `run`).
#ifndef LIGHT_TYPES_GLSL
#define LIGHT_TYPES_GLSL
#include "lighting.glsl"

bool light_is_directional() { return u.light_kind == LIGHT_DIRECTIONAL; }

// Whether world point p belongs to this view's cube face: the face whose axis
// is the largest component of p - light (ties go to x, then y, then z), so the
// six faces partition the directions and no point is lit twice.
bool in_cube_face(vec3 p, int face) {
    vec3 d = p - u.light_position;
    vec3 a = abs(d);
    int axis = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
    float sign = (face & 1) == 0 ? 1.0 : -1.0;
    return axis == face / 2 && d[axis] * sign > 0.0;
}

// Spot and point: radiant intensity toward p (W/sr, per channel), zero outside
// the spot's cone or cube face `face` (the RSM's layer, or this view's face).
// Directional: the irradiance E (W/m^2) on a surface facing the light.
vec3 light_intensity_toward(vec3 p, int face) {
    if (u.light_kind == LIGHT_SPOT) return spot_intensity(u, p);
    if (light_is_directional()) return u.light_intensity;
    if (!in_cube_face(p, face)) return vec3(0.0);
    vec3 i = u.light_intensity;
    if (u.light_range > 0.0) {
        float r = length(p - u.light_position) / u.light_range;
        i *= clamp(1.0 - r * r * r * r, 0.0, 1.0);
    }
    return i;
}

// Unit vector from p toward the light, and the squared distance r2 that
// divides the intensity (1 for a directional light: E needs no falloff).
vec3 light_direction_from(vec3 p, out float r2) {
    if (light_is_directional()) {
        r2 = 1.0;
        return -u.light_direction;
    }
    vec3 to_light = u.light_position - p;
    r2 = dot(to_light, to_light);
    return to_light * inversesqrt(r2);
}

// One RSM texel (docs/algorithm.md sections 2.3 and 2.4) at framebuffer
// coordinate frag seeing point x with normal n (cos_j floored at min_cos):
//   Phi_j = rho_j * intensity * measure; area: A_j (m^2); dw: dw_j (sr).
// Perspective (spot, cube face): dw_j = texel^2 cos^3 alpha on the unit image
// plane, Phi_j = rho I(w) dw_j, A_j = dw_j r^2 / cos_j. Orthographic: every
// texel has the same area a = texel^2 perpendicular to the light,
// Phi_j = rho E a, A_j = a / cos_j, and no solid angle (dw_j = 0).
void rsm_texel(vec3 x, vec2 frag, vec3 n, int face, float min_cos, out vec3 intensity,
               out float measure, out float area, out float dw) {
    float res = float(run.rsm_resolution);
    float half_extent = u.rsm_half_extent;
    float texel = 2.0 * half_extent / res;
    intensity = light_intensity_toward(x, face);
    bool lit = max(intensity.r, max(intensity.g, intensity.b)) > 0.0;
    if (light_is_directional()) {
        float a = texel * texel;
        float cos_j = max(dot(n, -u.light_direction), min_cos);
        measure = a;
        area = lit ? a / cos_j : 0.0;
        dw = 0.0;
        return;
    }
    // The texel center's point on the image plane at unit distance from the light.
    vec2 plane = (frag / res * 2.0 - 1.0) * half_extent;
    float cos_alpha = inversesqrt(1.0 + dot(plane, plane));
    dw = texel * texel * cos_alpha * cos_alpha * cos_alpha;
    vec3 to_light = u.light_position - x;
    float r2 = dot(to_light, to_light);
    float cos_j = max(dot(n, to_light * inversesqrt(r2)), min_cos);
    measure = dw;
    area = lit ? dw * r2 / cos_j : 0.0;
}

// Shadow lookup for receiver p (docs/algorithm.md section 2.2): how many metres
// one shadow-map texel spans at p, and the reference depth for a receiver at RSM
// depth z, with `slope` already in NDC depth (direct_light.frag: the
// receiver plane's gradient times the texels the compare spans). Perspective
// reversed-Z depth is near/z, so the constant bias is relative
// (d(near/z)/(near/z) = -dz/z); orthographic depth is linear, so it is an
// offset of the depth range.
float shadow_texel_world(vec3 p) {
    float res = float(run.shadow_resolution);
    if (light_is_directional()) return 2.0 * u.shadow_half_extent / res;
    float dist = dot(p - u.light_position, u.light_direction);
    return 2.0 * u.shadow_half_extent * max(dist, 0.0) / res;
}

float shadow_reference(float z, float slope) {
    if (light_is_directional()) return z + run.shadow_depth_bias + slope;
    return z * (1.0 + run.shadow_depth_bias) + slope;
}

// The length that ISR's relative depth threshold multiplies for a child at
// p (rsm_tree.comp): its distance to the light for perspective RSMs, where a
// texel's footprint grows with distance. An orthographic texel's footprint
// is the same everywhere (texel = 2 h / R, h = light_cone.z), equal to a
// 90 degree perspective texel's at distance h: so h, which keeps the test's
// meaning (depth offsets measured in texel footprints times R / 2).
float validity_reach(vec3 p) {
    if (light_is_directional()) return u.rsm_half_extent;
    return distance(p, u.light_position);
}

#endif
