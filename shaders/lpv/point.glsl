// Method lpv: splatting one value into one cell of the grid by rasterizing a
// triangle that covers exactly that texel of the layer (docs/algorithm.md
// section 8.2). Float atomics are not core Vulkan; additive blending into
// float colour attachments is. Include after lpv/lpv.glsl.
#ifndef LPV_POINT_GLSL
#define LPV_POINT_GLSL

// Corner `corner` (0..2, gl_VertexIndex % 3) of the triangle covering texel
// `cell.xy` of an N x N layer: corners at (-1/2, -1/2), (1, -1/2) and
// (-1/2, 1) texels from the texel's centre. The centre lies inside it
// (x + y < 3/2 there), every other texel centre outside, so it rasterizes
// exactly one fragment whatever the rasterization rules.
vec4 lpv_point_corner(ivec3 cell, int corner) {
    vec2 offset = corner == 0 ? vec2(-0.5, -0.5) : (corner == 1 ? vec2(1.0, -0.5) : vec2(-0.5, 1.0));
    vec2 texel = vec2(cell.xy) + 0.5 + offset;
    return vec4(texel / float(LPV_SIZE) * 2.0 - 1.0, 0.0, 1.0);
}

// A position that rasterizes nothing (all three corners at it).
const vec4 LPV_NOWHERE = vec4(2.0, 2.0, 0.0, 1.0);

#endif
