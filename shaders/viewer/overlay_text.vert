#version 460
#extension GL_GOOGLE_include_directive : require
// The overlay's one quad (two triangles): the text grid plus one glyph pixel
// around it for the glyphs' dark outline.
#include "shared.glsl"

layout(push_constant) uniform Push { OverlayPush p; };

void main() {
    // Corners 0..3 of the quad, in the order of two triangles.
    const int corner[6] = int[6](0, 1, 2, 2, 1, 3);
    int c = corner[gl_VertexIndex];
    int scale = p.target.z;
    vec2 lo = vec2(p.rect.xy - scale);
    vec2 hi = vec2(p.rect.xy + p.rect.zw * 8 * scale + scale);
    vec2 px = vec2((c & 1) != 0 ? hi.x : lo.x, (c & 2) != 0 ? hi.y : lo.y);
    gl_Position = vec4(px / vec2(p.target.xy) * 2.0 - 1.0, 0.0, 1.0);
}
