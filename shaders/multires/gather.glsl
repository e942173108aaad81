// The stenciled gather's frame (docs/algorithm.md section 3, step 6), the
// same for every light-space source: one draw over every layer of the
// illumination buffer; the stencil test (EQUAL 1) runs before the shader, so
// only patches are shaded. Each patch sums C_{j->i} / rho_i over its light
// patches at its mean position and normal. Which light patches is the
// source's (docs/algorithm.md section 4, `multires::LightSource`): its
// fragment shader declares its own bindings of set 1 from
// GATHER_SOURCE_BINDING on, includes this file and defines
//   void gather_patches(vec3 xi, vec3 ni, ivec2 p)
// which adds each light patch it evaluates with add_patch
// (multires/gather_list.frag for a list of light patches, hisr/gather.frag
// for HISR's traversal). With the stencil off (a measurement baseline) every
// texel is shaded and non-patches are masked afterwards.
#ifndef GATHER_FRAME_GLSL
#define GATHER_FRAME_GLSL
#include "frame.glsl"
#include "light_types.glsl"
#include "vpl.glsl"

layout(early_fragment_tests) in;

layout(set = 1, binding = 0) uniform sampler2D geo_mean;    // levels 1..L (multires/geo_levels.glsl)
layout(set = 1, binding = 1) uniform sampler2D geo_normal;  // levels 1..L
layout(set = 1, binding = 2) uniform usampler2D geo_flags;  // levels 1..L
layout(set = 1, binding = 3) uniform sampler2D gbuffer_position;  // level 0
layout(set = 1, binding = 4) uniform sampler2D gbuffer_normal;
// The source's first binding (multires::gather::SOURCE_BINDING).
#define GATHER_SOURCE_BINDING 5
#define GEO_FLAGS
#include "multires/geo_levels.glsl"

layout(location = 0) flat in int level;  // the layer (multires/layered.vert)

layout(location = 0) out vec4 out_irradiance;  // rgb: E (W/m^2); a: 1 = this texel is a patch
layout(location = 1) out float out_evaluations; // light patches evaluated (a count, R32F so splats can add)

vec3 e = vec3(0.0);
uint evaluations = 0u;

// level: patch_level of the patch (patch_irradiance).
// march: whether to march (patch_irradiance) or apply visibility v. Callers
// pass a constant: the driver then drops the march where it is false, whose
// mere presence in the traversal's loop cost lavapipe as much as the rest of
// the gather.
void add_patch(vec3 xi, vec3 ni, vec4 pos, vec4 nrm, vec3 flux, int level, bool march, float v) {
    if (!march) {
        e += v * patch_unshadowed(xi, ni, pos.xyz, nrm.xyz, flux, pos.w, level);
    } else {
        e += patch_irradiance(xi, ni, pos.xyz, nrm.xyz, flux, pos.w, level);
    }
    evaluations += 1u;
}

// The source's: adds the light patches of the receiver at xi (unit normal
// ni), eye-space texel p of this level.
void gather_patches(vec3 xi, vec3 ni, ivec2 p);

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 xi = geo_mean_at(p, level).xyz;
    vec3 ni = geo_normal_at(p, level).xyz;
    gather_patches(xi, ni, p);
    float is = 1.0;
    if ((run.hierarchy_flags & HIERARCHY_STENCIL_OFF) != 0 && !is_patch(level, run.levels, p)) {
        is = 0.0;
        e = vec3(0.0);
        evaluations = 0u;
    }
    out_irradiance = vec4(e, is);
    out_evaluations = float(evaluations);
}

#endif
