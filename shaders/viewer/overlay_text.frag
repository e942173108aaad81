#version 460
#extension GL_GOOGLE_include_directive : require
// The overlay's text: each fragment finds its glyph cell and the glyph's bit
// (8x8 bitmap font, one byte per row, bit 0 leftmost); lit bits are drawn in
// the cell's colour, unlit ones next to a lit one dark (an outline that keeps
// the text readable on any background), the rest discarded.
#include "shared.glsl"

// Set 0 is the frame set, as in every pipeline (unused here).
layout(set = 1, binding = 0, std430) readonly buffer Text { uint cells[]; };
layout(set = 1, binding = 1, std430) readonly buffer Font { uint rows[]; };  // 128 glyphs x 8 bytes

layout(push_constant) uniform Push { OverlayPush p; };

layout(location = 0) out vec4 out_color;

// The cell's value, or 0 outside the grid.
uint cell_at(ivec2 cell) {
    if (any(lessThan(cell, ivec2(0))) || any(greaterThanEqual(cell, p.rect.zw))) {
        return 0u;
    }
    return cells[cell.y * p.rect.z + cell.x];
}

// Whether glyph pixel `g` (in glyph pixels from the grid's corner) is lit.
bool lit(ivec2 g) {
    ivec2 cell = ivec2(floor(vec2(g) / 8.0));
    uint ch = cell_at(cell) & 127u;
    ivec2 in_cell = g - cell * 8;
    uint byte_index = ch * 8u + uint(in_cell.y);
    uint row = (rows[byte_index >> 2] >> ((byte_index & 3u) * 8u)) & 255u;
    return ((row >> uint(in_cell.x)) & 1u) != 0u;
}

const vec3 COLOURS[4] = vec3[4](vec3(1.0), vec3(1.0, 0.85, 0.3), vec3(0.65), vec3(0.45, 0.9, 1.0));

void main() {
    ivec2 g = ivec2(floor((gl_FragCoord.xy - vec2(p.rect.xy)) / float(p.target.z)));
    if (lit(g)) {
        uint colour = (cell_at(ivec2(floor(vec2(g) / 8.0))) >> 8) & 3u;
        out_color = vec4(COLOURS[colour], 1.0);
        return;
    }
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            if (lit(g + ivec2(dx, dy))) {
                out_color = vec4(0.0, 0.0, 0.0, 1.0);
                return;
            }
        }
    }
    discard;
}
