#version 460
// Stenciled refinement (docs/algorithm.md section 3, step 4), one pass over every
// layer: a fragment survives, and the stencil op writes 1, iff its texel is a
// patch. Surviving fragments are also counted per level for --stats.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(location = 0) flat in int level;  // the layer (layered.vert)
layout(set = 1, binding = 0) uniform usampler2D geo_flags;  // levels 1..L (geo_levels.glsl)
layout(set = 1, binding = 1, std430) buffer PatchCounts { uint patches_per_level[]; };
layout(set = 1, binding = 2) uniform sampler2D gbuffer_position;  // level 0
layout(set = 1, binding = 3) uniform sampler2D gbuffer_normal;
#define GEO_NO_MEANS
#define GEO_FLAGS
#include "geo_levels.glsl"

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (!is_patch(level, run.hierarchy.x, p)) discard;
    atomicAdd(patches_per_level[level], 1u);
}
