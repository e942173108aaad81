#version 460
#extension GL_ARB_shader_viewport_layer_array : require
// Method multires-splat (docs/algorithm.md section 5, Nichols & Wyman I3D 2009):
// every VPL splats into every layer of the multiresolution buffer; the stencil
// (EQUAL 1) keeps only the patches. Instance i is VPL i / (L + 1) on layer
// i % (L + 1), one quad covering that layer's used corner. Empty VPLs draw
// nothing.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(set = 1, binding = 2) uniform sampler2D rsm_position;
layout(set = 1, binding = 3) uniform sampler2D rsm_normal;
layout(set = 1, binding = 4) uniform sampler2D rsm_flux;
#include "regular_vpls/regular_vpls.glsl"

layout(location = 0) flat out int out_level;
layout(location = 1) flat out vec4 out_position;  // xyz: x_j; w: A_j
layout(location = 2) flat out vec4 out_normal;  // w: patch_level
layout(location = 3) flat out vec3 out_flux;

void main() {
    int layers = run.levels + 1;
    int level = gl_InstanceIndex % layers;
    vec4 pos, nrm;
    vec3 flux;
    bool live = regular_vpl(gl_InstanceIndex / layers, pos, nrm, flux);
    vec2 corner = vec2(run.output_size >> uint(level)) / vec2(run.output_size);
    const vec2 quad[6] = vec2[6](vec2(0, 0), vec2(1, 0), vec2(0, 1), vec2(1, 0), vec2(1, 1), vec2(0, 1));
    vec2 p = quad[gl_VertexIndex];
    gl_Position = live ? vec4(p * corner * 2.0 - 1.0, 0.0, 1.0) : vec4(2.0, 2.0, 0.0, 1.0);
    gl_Layer = level;
    out_level = level;
    out_position = pos;
    out_normal = nrm;
    out_flux = flux;
}
