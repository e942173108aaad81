#version 460
#extension GL_GOOGLE_include_directive : require
// Reflective shadow map of a point light's cube face f (docs/algorithm.md
// section 2.4), drawn with rsm_cube.vert into layer f: see rsm_texel.glsl.
#include "rsm_texel.glsl"

layout(location = 3) flat in int in_face;  // the layer: cube face +x, -x, +y, -y, +z, -z

void main() { write_rsm_texel(in_face); }
