#version 460
// Method lpv, pass lpv-inject (docs/algorithm.md section 8.2): the fragment
// of a VPL's cell adds its intensity's SH into the three injection images
// (one per colour channel; blend ONE + ONE into RGBA32F).

layout(location = 0) flat in vec4 in_red;
layout(location = 1) flat in vec4 in_green;
layout(location = 2) flat in vec4 in_blue;

layout(location = 0) out vec4 out_red;
layout(location = 1) out vec4 out_green;
layout(location = 2) out vec4 out_blue;

void main() {
    out_red = in_red;
    out_green = in_green;
    out_blue = in_blue;
}
