#version 460
// Method lpv, pass lpv-geometry (docs/algorithm.md section 8.3): a surfel's
// fragment adds its blocking potential's SH into the geometry volume
// (blend ONE + ONE).

layout(location = 0) flat in vec4 in_blocking;
layout(location = 0) out vec4 out_blocking;

void main() {
    out_blocking = in_blocking;
}
