#version 460
// Stenciled gathering (ALGORITHM.md section 3, step 6): one draw over every
// layer; the stencil test (EQUAL 1) runs before the shader, so only patches
// are shaded. Each patch sums the irradiance of the regular VPLs, level k of
// the RSM quadtree (ALGORITHM.md section 4, "Regular N VPLs"), at its mean
// position and normal. With the stencil off (a measurement baseline) every
// texel is shaded and non-patches are masked afterwards.
#extension GL_GOOGLE_include_directive : require
#include "shared.glsl"
#include "lighting.glsl"
#include "multires.glsl"
#include "vpl.glsl"

layout(early_fragment_tests) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms u; };
layout(location = 0) flat in int level;  // the layer (layered.vert)
layout(set = 0, binding = 1) uniform sampler2D geo_mean;    // mip chain
layout(set = 0, binding = 2) uniform sampler2D geo_normal;  // mip chain
layout(set = 0, binding = 3) uniform usampler2D geo_flags;  // mip chain
layout(set = 0, binding = 4) uniform sampler2D rsm_position;  // quadtree (mip chain)
layout(set = 0, binding = 5) uniform sampler2D rsm_normal;
layout(set = 0, binding = 6) uniform sampler2D rsm_flux;

layout(location = 0) out vec4 out_irradiance;  // rgb: E (W/m^2); a: 1 = this texel is a patch

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 xi = texelFetch(geo_mean, p, level).xyz;
    vec3 ni = texelFetch(geo_normal, p, level).xyz;
    int k = u.hierarchy.y;
    int side = u.hierarchy.z;
    bool point = (u.hierarchy.w & HIERARCHY_POINT_VPLS) != 0;
    int span = 1 << k;  // RSM texels per VPL side
    vec3 e = vec3(0.0);
    for (int y = 0; y < side; ++y) {
        for (int x = 0; x < side; ++x) {
            vec4 pos, nrm, flux;
            if (point) {
                // The texel at the patch's centre, standing for all 4^k texels.
                ivec2 t = ivec2(x, y) * span + span / 2;
                pos = texelFetch(rsm_position, t, 0);
                nrm = texelFetch(rsm_normal, t, 0);
                flux = texelFetch(rsm_flux, t, 0) * float(span * span);
                pos.w *= float(span * span);
            } else {
                pos = texelFetch(rsm_position, ivec2(x, y), k);
                nrm = texelFetch(rsm_normal, ivec2(x, y), k);
                flux = texelFetch(rsm_flux, ivec2(x, y), k);
            }
            if (pos.w <= 0.0) continue;  // the patch saw nothing
            e += patch_irradiance(xi, ni, pos.xyz, nrm.xyz, flux.rgb, pos.w);
        }
    }
    float is = 1.0;
    if ((u.hierarchy.w & HIERARCHY_STENCIL_OFF) != 0 && !is_patch(geo_flags, level, u.hierarchy.x, p)) {
        is = 0.0;
        e = vec3(0.0);
    }
    out_irradiance = vec4(e, is);
}
