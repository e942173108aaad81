#version 460
// Method rsm-gather (docs/algorithm.md section 5, Dachsbacher & Stamminger 2005):
// every full-resolution pixel gathers the N regular VPLs,
//   E = sum_j Phi_j cos_i cos_j / (pi d^2 + A_j).
// Pass `reference` runs the same shader over every RSM texel (N = R^2), a
// band of VPL rows per submission, adding into the target.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 1, binding = 2) uniform sampler2D rsm_position;  // quadtree (mip chain)
layout(set = 1, binding = 3) uniform sampler2D rsm_normal;
layout(set = 1, binding = 4) uniform sampler2D rsm_flux;
#include "regular_vpls/regular_vpls.glsl"

// VPLs first .. last - 1 (row-major); the whole set unless `reference` splits it.
layout(push_constant) uniform Push { int first; int last; };

layout(location = 0) out vec4 out_irradiance;  // rgb: E (W/m^2)

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(gbuffer_position, pixel, 0);
    vec3 e = vec3(0.0);
    if (p.w > 0.0) {
        vec3 n = normalize(texelFetch(gbuffer_normal, pixel, 0).xyz);
        for (int j = first; j < min(last, regular_vpl_count()); ++j) {
            vec4 pos, nrm;
            vec3 flux;
            if (regular_vpl(j, pos, nrm, flux)) e += patch_irradiance(p.xyz, n, pos.xyz, nrm.xyz, flux, pos.w, int(nrm.w));
        }
    }
    out_irradiance = vec4(e, 0.0);
}
