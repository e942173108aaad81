// Reflective shadow map (docs/algorithm.md sections 2.3 and 2.4). Texel j holds the point
// x_j it sees, its normal n_j, the VPL flux Phi_j = rho_j * I(w_j) * dw_j and world
// area A_j = dw_j * r_j^2 / cos_j (spot, cube face), or Phi_j = rho_j E a and
// A_j = a / cos_j (directional, texel area a); see light_types.glsl. Depth goes
// to the depth attachment. Shared by rsm.frag (spot, directional) and
// rsm_cube.frag (a point light's six faces in one layered draw).
#ifndef RSM_TEXEL_GLSL
#define RSM_TEXEL_GLSL
#include "frame.glsl"
#include "light_types.glsl"

layout(push_constant) uniform Push { DrawPush draw; };
#include "material.glsl"

layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

// The layout every level of the RSM quadtree shares (see rsm_tree.comp).
layout(location = 0) out vec4 out_position;  // xyz: x_j (m); w: A_j (m^2), 0 where nothing lit was seen
layout(location = 1) out vec4 out_normal;    // xyz: n_j; w: PATCH_VALID (1) where lit geometry was seen
layout(location = 2) out vec4 out_flux;      // rgb: Phi_j (W); a: dw_j (sr)

// Smallest cosine used for A_j: a surface seen edge-on by the light would get an
// unbounded area; 0.01 caps it at 100x the facing area.
const float MIN_COS_J = 0.01;

// Writes the texel; `face` is the cube face of a point light (else unused).
void write_rsm_texel(int face) {
    vec3 n = facing_normal(in_normal);
    vec3 intensity;
    float measure, area, dw;
    rsm_texel(in_world, gl_FragCoord.xy, n, face, MIN_COS_J, intensity, measure, area, dw);
    vec3 albedo = material_albedo(draw.material, in_uv);
    // Texels outside the cone (about 21% of a square RSM around a round cone)
    // or outside a cube face carry no power: they are empty patches (area 0),
    // so no light-space method spends work on them and they do not pull the
    // means of patches on the cone edge.
    bool lit = area > 0.0;
    out_position = vec4(in_world, area);
    out_normal = vec4(n, lit ? 1.0 : 0.0);
    out_flux = vec4(albedo * intensity * measure, dw);
}

#endif
