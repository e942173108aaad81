#version 460
#extension GL_GOOGLE_include_directive : require
// Method lpv, pass lpv-lookup (docs/algorithm.md section 8.5): every pixel
// reads the propagated intensity from the finest cascade that holds it,
// half a cell along its normal, interpolated trilinearly between cell
// centres, and turns it into irradiance: a cell of side h whose light has
// intensity I(w) carries radiance I(w) / h^2, so
//   E = 1/h^2 * integral I(w) max(0, -n.w) dw = max(0, <I, cos(-n)>) / h^2
// (the SH dot product). Within BLEND cells of a cascade's border the next
// coarser cascade is blended in; outside the coarsest there is no light.
#include "frame.glsl"
#include "lpv/lpv.glsl"

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 1, binding = 2, std430) readonly buffer LpvSum { vec4 sum[]; };

layout(location = 0) out vec4 out_irradiance;  // rgb: E (W/m^2)

// Cells over which a cascade hands over to the next coarser one.
const int BLEND = LPV_SIZE >= 8 ? LPV_SIZE / 8 : 1;  // Layout::blend_cells

// Irradiance at p (normal n) from cascade c, at cell-centre coordinates g.
vec3 cascade_irradiance(int c, vec3 g, vec3 n) {
    vec3 lo = clamp(floor(g), vec3(0.0), vec3(LPV_SIZE - 2));
    vec3 f = clamp(g - lo, vec3(0.0), vec3(1.0));
    ivec3 base = ivec3(lo);
    vec4 r = vec4(0.0), gr = vec4(0.0), b = vec4(0.0);
    for (int i = 0; i < 8; ++i) {
        ivec3 o = ivec3(i & 1, (i >> 1) & 1, i >> 2);
        vec3 t = mix(1.0 - f, f, vec3(o));
        float w = t.x * t.y * t.z;
        int j = lpv_cell_index(c, base + o);
        r += w * sum[j];
        gr += w * sum[LPV_CELLS + j];
        b += w * sum[2 * LPV_CELLS + j];
    }
    vec4 lobe = sh_cosine_lobe(-n);
    float h = lpv_cell_size(c);
    return max(vec3(dot(r, lobe), dot(gr, lobe), dot(b, lobe)), vec3(0.0)) / (h * h);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(gbuffer_position, pixel, 0);
    vec3 e = vec3(0.0);
    if (p.w > 0.0) {
        vec3 n = normalize(texelFetch(gbuffer_normal, pixel, 0).xyz);
        float remaining = 1.0;
        for (int c = 0; c < LPV_CASCADES && remaining > 0.0; ++c) {
            vec3 g = lpv_grid_position(c, p.xyz + 0.5 * lpv_cell_size(c) * n) - 0.5;
            vec3 inner = min(g, vec3(LPV_SIZE - 1) - g);
            float depth = min(inner.x, min(inner.y, inner.z));
            float w = c + 1 == LPV_CASCADES ? (depth >= -0.5 ? 1.0 : 0.0) : clamp(depth / float(BLEND), 0.0, 1.0);
            if (w > 0.0) {
                e += remaining * w * cascade_irradiance(c, g, n);
                remaining *= 1.0 - w;
            }
        }
    }
    out_irradiance = vec4(e, 0.0);
}
