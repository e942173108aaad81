#version 460
#extension GL_GOOGLE_include_directive : require
// Reflective shadow map of a spot or directional light (docs/algorithm.md
// sections 2.3 and 2.4), drawn with scene.vert: see rsm_texel.glsl.
#include "rsm_texel.glsl"

void main() { write_rsm_texel(u.cube_face); }
