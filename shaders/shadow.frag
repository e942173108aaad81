#version 460
// The direct light's shadow map (docs/algorithm.md section 2.2), drawn with
// scene.vert (VIEW_FROM_LIGHT = 2): depth only, so nothing to write. The
// inputs are scene.vert's outputs, declared so the interfaces match.
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

void main() {}
