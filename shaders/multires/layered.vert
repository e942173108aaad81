#version 460
#extension GL_ARB_shader_viewport_layer_array : require
// One quad (6 vertices) per layer of the multiresolution buffer (docs/algorithm.md
// section 3, step 5): instance l draws into layer l and covers exactly its used
// corner, (W >> l) x (H >> l) texels, so no fragment falls on the unused rest.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"


// The level, for fragment shaders: reading gl_Layer there would need the
// Geometry capability (geometry shaders), which not every GPU has.
layout(location = 0) flat out int out_level;

void main() {
    int level = gl_InstanceIndex;
    vec2 corner = vec2(run.output_size >> uint(level)) / vec2(run.output_size);
    // Two triangles: (0,0) (1,0) (0,1) and (1,0) (1,1) (0,1).
    const vec2 quad[6] = vec2[6](vec2(0, 0), vec2(1, 0), vec2(0, 1), vec2(1, 0), vec2(1, 1), vec2(0, 1));
    vec2 p = quad[gl_VertexIndex];
    gl_Position = vec4(p * corner * 2.0 - 1.0, 0.0, 1.0);
    gl_Layer = level;
    out_level = level;
}
