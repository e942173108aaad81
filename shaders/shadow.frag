#version 460
// The direct light's shadow map (docs/algorithm.md section 2.2), drawn with
// scene.vert (VIEW_FROM_LIGHT = 2): depth only, so nothing to write here.
void main() {}
