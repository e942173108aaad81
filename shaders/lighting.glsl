// Spot light radiometry (docs/algorithm.md section 2) shared by the RSM and direct passes.
#ifndef LIGHTING_GLSL
#define LIGHTING_GLSL

// Radiant intensity (W/sr) of the spot light toward world point p, per channel:
// KHR_lights_punctual angular attenuation (squared smooth ramp between the
// cones) and, when a range is set, the extension's range window.
vec3 spot_intensity(FrameUniforms u, vec3 p) {
    vec3 to_p = p - u.light_position;
    float d = length(to_p);
    float cd = dot(u.light_direction, to_p / max(d, 1e-20));
    float t = clamp(cd * u.cone_scale + u.cone_offset, 0.0, 1.0);
    vec3 i = u.light_intensity * (t * t);
    if (u.light_range > 0.0) {
        float r = d / u.light_range;
        i *= clamp(1.0 - r * r * r * r, 0.0, 1.0);
    }
    return i;
}

#endif
