#version 460
#extension GL_ARB_shader_viewport_layer_array : require
// One triangle per layer of the multiresolution buffer (ALGORITHM.md section 3,
// step 5): instance l draws into layer l and covers only its used corner,
// (W >> l) x (H >> l) texels, so no work is spent on the unused rest.
#extension GL_GOOGLE_include_directive : require
#include "shared.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms u; };

void main() {
    int level = gl_InstanceIndex;
    vec2 corner = vec2(u.size.xy >> uint(level)) / vec2(u.size.xy);
    vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);  // 0..2, covers 0..1 with the rest clipped
    gl_Position = vec4(p * corner * 2.0 - 1.0, 0.0, 1.0);
    gl_Layer = level;
}
