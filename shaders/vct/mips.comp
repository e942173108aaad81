#version 460
#extension GL_GOOGLE_include_directive : require
// Method vct, pass vct-mips (docs/algorithm.md section 9.2), one dispatch
// per level, one invocation per cell of the level. Three volumes:
// radiance (premultiplied colour, opacity), the lit surface's lobe and the
// surface's lobe.
//
// Level 0, from a cell's injection sums and the surface inside it (the
// voxel grid's `voxel-surface` sums: area A_s in cell faces, normal sum):
//   A     = A_s, or A_rsm where the grid's samples missed the surface the
//           RSM saw (A_s = 0). Not the larger: an RSM texel wider than a
//           cell puts all its flux (and area) in the one cell holding its
//           centre, and spreading that flux over the texel's area there
//           would lose the rest of it (9x in the box at R = 64, 64^3).
//           The cell emits exactly the flux it holds, L alpha pi h^2 = Phi
//           for A >= 1.
//   alpha = min(1, A)                (a cell face of surface blocks the cell)
//   L     = Phi / (pi A h^2)         (the outgoing radiance of the surface in
//                                      it, W/(m^2 sr): all of its area shares
//                                      the flux, lit or not)
// radiance (L alpha, alpha); lit lobe (m w, w): the lit surface's mean
// normal m = sum(n Phi) / sum(Phi) (its length falls where normals
// disagree) times w = mean(L alpha); surface lobe (s alpha, alpha): the
// surface's mean normal s = sum(n A) / A.
//
// Level k + 1 from the 8 cells under it. Opacity is composited, not
// averaged: along each axis the two cells of each of the 4 columns in
// turn, 1 - (1 - a_front)(1 - a_back), averaged over the columns, and the
// largest of the three axes kept. A wall one cell thick stays opaque at
// every level seen across it, where the mean would make it 2^-k opaque
// and let cones run out of the grid before they gather its light
// (docs/experiments.md). Colour keeps the children's opacity-weighted mean
// radiance: c = mean(c_i) / mean(a_i) * alpha. The lobes are means.
#include "frame.glsl"
#include "vct/vct.glsl"
#include "voxel_grid/surface.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, std430) readonly buffer GridSurface { uint surface[]; };
layout(set = 1, binding = 1, std430) readonly buffer VctAccum { uint accum[]; };
layout(set = 1, binding = 2, rgba32f) uniform readonly image3D source_radiance;
layout(set = 1, binding = 3, rgba32f) uniform readonly image3D source_lobe;
layout(set = 1, binding = 4, rgba32f) uniform readonly image3D source_surface;
layout(set = 1, binding = 5, rgba32f) uniform writeonly image3D target_radiance;
layout(set = 1, binding = 6, rgba32f) uniform writeonly image3D target_lobe;
layout(set = 1, binding = 7, rgba32f) uniform writeonly image3D target_surface;
layout(push_constant) uniform Push { int level; };

void main() {
    int m = VCT_SIZE >> level;
    ivec3 c = ivec3(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y % uint(m),
                    gl_GlobalInvocationID.y / uint(m));
    if (c.x >= m || c.z >= m) {
        return;
    }
    vec4 radiance = vec4(0.0), lobe = vec4(0.0), facing = vec4(0.0);
    if (level == 0) {
        int i = vct_cell_index(c);
        uint base = uint(i) * ACCUM_WORDS;
        uint s = uint(i) * SURFACE_WORDS;
        float a_s = float(surface[s]) / SURFACE_ONE;
        float area = a_s > 0.0 ? a_s : float(accum[base + 3u]) / AREA_ONE;
        if (area > 0.0) {
            float unit = vct_flux_unit();
            vec3 flux = vec3(accum[base], accum[base + 1u], accum[base + 2u]) * unit;
            float h = u.grid_cube.w;
            float alpha = min(area, 1.0);
            vec3 l = flux / (PI * area * h * h);
            radiance = vec4(l * alpha, alpha);
            float lum = (flux.r + flux.g + flux.b) / 3.0;
            vec3 n = vec3(ivec3(accum[base + 4u], accum[base + 5u], accum[base + 6u])) * unit;
            vec3 mean = lum > 0.0 ? n / lum : vec3(0.0);
            float w = (radiance.r + radiance.g + radiance.b) / 3.0;
            lobe = vec4(mean * w, w);
            vec3 ns = vec3(ivec3(surface[s + 4u], surface[s + 5u], surface[s + 6u])) / SURFACE_ONE;
            facing = vec4((a_s > 0.0 ? ns / a_s : vec3(0.0)) * alpha, alpha);
        }
    } else {
        float a[8];
        float mean_a = 0.0;
        vec3 mean_c = vec3(0.0);
        for (int j = 0; j < 8; ++j) {
            ivec3 child = 2 * c + ivec3(j & 1, (j >> 1) & 1, j >> 2);
            vec4 r = imageLoad(source_radiance, child);
            a[j] = r.a;
            mean_a += r.a;
            mean_c += r.rgb;
            lobe += imageLoad(source_lobe, child);
            facing += imageLoad(source_surface, child);
        }
        mean_a *= 0.125;
        mean_c *= 0.125;
        lobe *= 0.125;
        facing *= 0.125;
        float alpha = 0.0;
        for (int axis = 0; axis < 3; ++axis) {
            int bit = 1 << axis;
            float columns = 0.0;
            for (int j = 0; j < 8; ++j) {
                if ((j & bit) == 0) {
                    columns += 1.0 - (1.0 - a[j]) * (1.0 - a[j | bit]);
                }
            }
            alpha = max(alpha, 0.25 * columns);
        }
        radiance = vec4(mean_a > 0.0 ? mean_c * (alpha / mean_a) : vec3(0.0), alpha);
    }
    imageStore(target_radiance, c, radiance);
    imageStore(target_lobe, c, lobe);
    imageStore(target_surface, c, facing);
}
