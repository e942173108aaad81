#version 460
// One level of the RSM quadtree (docs/algorithm.md section 2, "A patch P"): each
// texel of level k merges its four children of level k-1. Flux and solid angle
// add up, area adds up, position is the flux-weighted mean (the area-weighted
// one where the patch has no flux) and the normal the normalised
// area-weighted mean. Flux-weighted: each texel's contribution is its flux
// times a kernel of its position, so about that mean the first-order terms of
// the kernel cancel however the flux varies over the patch (a cone's edge,
// a texture), where about the area-weighted mean they do not.
//
// Validity (normal.w, see PATCH_*): a patch is valid when all its non-empty
// children are valid and lie on one surface: each child's mean within the
// depth threshold (relative to its distance to the light, or for an orthographic
// RSM to its half side: validity_reach in light_types.glsl) of the patch's
// plane, and its normal within the angle threshold of the patch's normal.
// Children's means are compared rather than full ranges, so a patch keeps only
// a flag; since validity needs valid children, a discontinuity anywhere below
// invalidates every ancestor.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "light_types.glsl"
layout(local_size_x = 8, local_size_y = 8) in;


layout(set = 1, binding = 0, rgba32f) readonly uniform image2D src_position;  // xyz: position; w: area A
layout(set = 1, binding = 1, rgba32f) readonly uniform image2D src_normal;    // xyz: normal; w: PATCH_*
layout(set = 1, binding = 2, rgba32f) readonly uniform image2D src_flux;      // rgb: flux; a: solid angle
layout(set = 1, binding = 3, rgba32f) writeonly uniform image2D dst_position;
layout(set = 1, binding = 4, rgba32f) writeonly uniform image2D dst_normal;
layout(set = 1, binding = 5, rgba32f) writeonly uniform image2D dst_flux;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(dst_position)))) return;
    vec4 flux = vec4(0.0);
    vec3 weighted_position = vec3(0.0);
    vec3 weighted_normal = vec3(0.0);
    vec3 flux_position = vec3(0.0);  // positions weighted by the flux's luminance
    float flux_weight = 0.0;
    float area = 0.0;
    bool children_valid = true;
    vec4 child_position[4];
    vec4 child_normal[4];
    for (int i = 0; i < 4; ++i) {
        ivec2 c = 2 * p + ivec2(i & 1, i >> 1);
        child_position[i] = imageLoad(src_position, c);
        child_normal[i] = imageLoad(src_normal, c);
        vec4 child_flux = imageLoad(src_flux, c);
        flux += child_flux;
        float luminance = dot(child_flux.rgb, vec3(0.2126, 0.7152, 0.0722));
        flux_position += luminance * child_position[i].xyz;
        flux_weight += luminance;
        weighted_position += child_position[i].w * child_position[i].xyz;
        weighted_normal += child_position[i].w * child_normal[i].xyz;
        area += child_position[i].w;
        children_valid = children_valid && child_normal[i].w != PATCH_INVALID;
    }
    vec3 position = flux_weight > 0.0 ? flux_position / flux_weight
                  : area > 0.0        ? weighted_position / area
                                      : vec3(0.0);
    vec3 normal = dot(weighted_normal, weighted_normal) > 0.0 ? normalize(weighted_normal) : vec3(0.0);
    float state = PATCH_EMPTY;
    if (area > 0.0) {
        // One surface: every non-empty child's mean lies near the patch's plane
        // (offset along the mean normal under the depth threshold times its
        // distance to the light) and its normal within the angle of the mean.
        // A slanted plane passes however much its distance to the light varies.
        bool one_surface = children_valid;
        for (int i = 0; i < 4; ++i) {
            if (child_normal[i].w == PATCH_EMPTY) continue;
            float offset = abs(dot(child_position[i].xyz - position, normal));
            float reach = run.validity_depth * validity_reach(child_position[i].xyz);
            one_surface = one_surface && offset < reach && dot(child_normal[i].xyz, normal) > run.validity_normal_cos;
        }
        state = one_surface ? PATCH_VALID : PATCH_INVALID;
    }
    imageStore(dst_position, p, vec4(position, area));
    imageStore(dst_normal, p, vec4(normal, state));
    imageStore(dst_flux, p, flux);
}
