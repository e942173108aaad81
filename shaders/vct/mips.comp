#version 460
#extension GL_GOOGLE_include_directive : require
// Method vct, pass vct-mips (docs/algorithm.md section 9.2), one dispatch
// per level, one invocation per cell of the level.
//
// Level 0, from a cell's injection sums and the surface inside it (the
// voxel grid's `voxel-surface` sums, area A_s in cell faces):
//   A     = max(A_s, A_rsm)          (the RSM may see surface the grid's
//                                      samples missed)
//   alpha = min(1, A)                (a cell face of surface blocks the cell)
//   L     = Phi / (pi A h^2)         (the outgoing radiance of the surface in
//                                      it, W/(m^2 sr): all of its area shares
//                                      the flux, lit or not)
// stored premultiplied: (L alpha, alpha). The lobe: the lit surface's mean
// normal m = sum(n Phi) / sum(Phi) (its length falls where normals
// disagree) times the premultiplied luminance w = mean(L alpha): (m w, w).
//
// Level k + 1: the mean of the 8 cells under it, for both volumes (colour
// premultiplied, so an empty child lowers opacity and colour together and
// the parent's colour per opacity is its children's opacity-weighted mean).
#include "frame.glsl"
#include "vct/vct.glsl"
#include "voxel_grid/surface.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, std430) readonly buffer GridSurface { uint surface[]; };
layout(set = 1, binding = 1, std430) readonly buffer VctAccum { uint accum[]; };
layout(set = 1, binding = 2, rgba32f) uniform readonly image3D source_radiance;
layout(set = 1, binding = 3, rgba32f) uniform readonly image3D source_lobe;
layout(set = 1, binding = 4, rgba32f) uniform writeonly image3D target_radiance;
layout(set = 1, binding = 5, rgba32f) uniform writeonly image3D target_lobe;
layout(push_constant) uniform Push { int level; };

void main() {
    int m = VCT_SIZE >> level;
    ivec3 c = ivec3(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y % uint(m),
                    gl_GlobalInvocationID.y / uint(m));
    if (c.x >= m || c.z >= m) {
        return;
    }
    vec4 radiance = vec4(0.0), lobe = vec4(0.0);
    if (level == 0) {
        int i = vct_cell_index(c);
        uint base = uint(i) * ACCUM_WORDS;
        float area = max(float(surface[uint(i) * SURFACE_WORDS]) / SURFACE_ONE,
                         float(accum[base + 3u]) / AREA_ONE);
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
        }
    } else {
        for (int j = 0; j < 8; ++j) {
            ivec3 child = 2 * c + ivec3(j & 1, (j >> 1) & 1, j >> 2);
            radiance += imageLoad(source_radiance, child);
            lobe += imageLoad(source_lobe, child);
        }
        radiance *= 0.125;
        lobe *= 0.125;
    }
    imageStore(target_radiance, c, radiance);
    imageStore(target_lobe, c, lobe);
}
