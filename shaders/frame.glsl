// The frame set (set 0) every pass binds: what changes per frame (camera,
// light, instance transforms) and what is fixed per run. `src/frame/mod.rs`
// makes one such set per frame in flight.
#ifndef FRAME_GLSL
#define FRAME_GLSL
#include "shared.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms u; };
layout(set = 0, binding = 1) uniform Run { RunUniforms run; };
layout(set = 0, binding = 2, std430) readonly buffer Transforms { InstanceTransform transforms[]; };
// Binding 3, the voxel visibility grid, is declared where it is used: read by
// the patch formula (voxel_grid/march.glsl), written by voxel_grid/voxelize.comp.

#endif
