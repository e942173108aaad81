#version 460
// Stenciled refinement (docs/algorithm.md section 3, step 4), one pass over every
// layer: a fragment survives, and the stencil op writes 1, iff its texel is a
// patch. Surviving fragments are also counted per level for --stats.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "multires.glsl"

layout(location = 0) flat in int level;  // the layer (layered.vert)
layout(set = 1, binding = 0) uniform usampler2D geo_flags;
layout(set = 1, binding = 1, std430) buffer PatchCounts { uint patches_per_level[]; };

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (!is_patch(geo_flags, level, run.hierarchy.x, p)) discard;
    atomicAdd(patches_per_level[level], 1u);
}
