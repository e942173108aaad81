#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_ARB_shader_viewport_layer_array : require
// Method lpv, pass lpv-inject (docs/algorithm.md section 8.2): every VPL (a
// texel of level LPV_LEVEL of the RSM quadtree: summed flux, area-weighted
// mean position and normal) is injected into every cascade that holds it,
// half a cell along its normal, as the intensity of a Lambertian emitter of
// its flux, I(w) = Phi / pi * max(0, n.w) W/sr, in 2-band SH. Triangle j / 3
// (corner j % 3) is VPL j / 3; instance c is cascade c; the triangle covers
// the VPL's cell in layer c * N + z (gl_Layer from the vertex shader).
#include "frame.glsl"
#include "lpv/lpv.glsl"
#include "lpv/point.glsl"

layout(constant_id = 44) const int LPV_LEVEL = 0;  // RSM quadtree level of the VPLs

layout(set = 1, binding = 0) uniform sampler2D rsm_position;  // quadtree (mip chain)
layout(set = 1, binding = 1) uniform sampler2D rsm_normal;
layout(set = 1, binding = 2) uniform sampler2D rsm_flux;

layout(location = 0) flat out vec4 out_red;    // SH of the VPL's intensity, per channel (W/sr)
layout(location = 1) flat out vec4 out_green;
layout(location = 2) flat out vec4 out_blue;

void main() {
    int vpl = gl_VertexIndex / 3;
    int c = gl_InstanceIndex;
    int side = int(run.rsm_resolution) >> LPV_LEVEL;
    ivec2 xy = ivec2(vpl % side, vpl / side);
    vec4 pos = texelFetch(rsm_position, xy, LPV_LEVEL);
    vec3 n = texelFetch(rsm_normal, xy, LPV_LEVEL).xyz;
    vec3 flux = texelFetch(rsm_flux, xy, LPV_LEVEL).rgb;
    vec3 p = pos.xyz + 0.5 * lpv_cell_size(c) * n;
    ivec3 cell = ivec3(floor(lpv_grid_position(c, p)));
    bool live = pos.w > 0.0 && any(greaterThan(flux, vec3(0.0))) && lpv_inside(cell);
    gl_Position = live ? lpv_point_corner(cell, gl_VertexIndex % 3) : LPV_NOWHERE;
    gl_Layer = c * LPV_SIZE + clamp(cell.z, 0, LPV_SIZE - 1);
    vec4 lobe = sh_cosine_lobe(n) / PI;
    out_red = flux.r * lobe;
    out_green = flux.g * lobe;
    out_blue = flux.b * lobe;
}
