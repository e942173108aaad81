#version 460
// Stenciled refinement (docs/algorithm.md section 3, step 4), one pass over every
// layer: a fragment survives, and the stencil op writes 1, iff its texel is a
// patch. In a frame that counts (src/vk/profiler.rs), surviving fragments are
// also counted per level for --stats; the other frames skip the atomics, which
// cost CPU drivers a fifth of the pass.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(location = 0) flat in int level;  // the layer (multires/layered.vert)
layout(set = 1, binding = 0) uniform usampler2D geo_flags;  // levels 1..L (multires/geo_levels.glsl)
layout(set = 1, binding = 1, std430) buffer PatchCounts { uint patches_per_level[]; };
layout(set = 1, binding = 2) uniform sampler2D gbuffer_position;  // level 0
layout(set = 1, binding = 3) uniform sampler2D gbuffer_normal;
#define GEO_NO_MEANS
#define GEO_FLAGS
#include "multires/geo_levels.glsl"

layout(constant_id = 13) const bool COUNT = true;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (!is_patch(level, run.levels, p)) discard;
    if (COUNT) atomicAdd(patches_per_level[level], 1u);
}
