#version 460
#extension GL_GOOGLE_include_directive : require
// Method vct, pass vct-inject (docs/algorithm.md section 9.1): every texel
// of the RSM (level 0: its point x_j, normal n_j, flux Phi_j and area A_j)
// adds its flux, area and flux-weighted normal to the sums of the cell that
// holds x_j, in fixed point with integer atomics (vct.glsl). Texels that
// saw nothing lit (A_j = 0) or fall outside the grid add nothing.
#include "frame.glsl"
#include "vct/vct.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0) uniform sampler2D rsm_position;  // xyz: x_j; w: A_j
layout(set = 1, binding = 1) uniform sampler2D rsm_normal;
layout(set = 1, binding = 2) uniform sampler2D rsm_flux;
layout(set = 1, binding = 3, std430) buffer VctAccum { uint accum[]; };

void main() {
    ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
    int r = int(run.rsm_resolution);
    if (xy.x >= r || xy.y >= r) {
        return;
    }
    vec4 pos = texelFetch(rsm_position, xy, 0);
    vec3 flux = max(texelFetch(rsm_flux, xy, 0).rgb, vec3(0.0));
    if (!(pos.w > 0.0) || all(equal(flux, vec3(0.0)))) {
        return;
    }
    vec3 n = texelFetch(rsm_normal, xy, 0).xyz;
    float h = u.grid_cube.w;
    // A hair behind the surface, so that a surface on a face between two
    // cells lands in one of them whatever rounding does.
    vec3 g = (pos.xyz - 1e-3 * h * n - u.grid_cube.xyz) / h;
    ivec3 c = ivec3(floor(g));
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(VCT_SIZE)))) {
        return;
    }
    uint base = uint(vct_cell_index(c)) * ACCUM_WORDS;
    // At most 2^31 / R^2 units a texel (vct.glsl), rounded to nearest.
    float unit = vct_flux_unit();
    float cap = 2147483648.0 / float(r * r);
    vec3 q = min(flux / unit, vec3(cap));
    uvec3 units = uvec3(q + 0.5);
    atomicAdd(accum[base + 0u], units.r);
    atomicAdd(accum[base + 1u], units.g);
    atomicAdd(accum[base + 2u], units.b);
    // Areas up to 64 cell faces a texel (a grazing texel's A_j is capped at
    // 100x its facing area; 64 faces is far past any texel at the sizes run).
    atomicAdd(accum[base + 3u], uint(min(pos.w / (h * h), 64.0) * AREA_ONE + 0.5));
    ivec3 nq = ivec3(round(n * (q.r + q.g + q.b) / 3.0));
    atomicAdd(accum[base + 4u], uint(nq.x));
    atomicAdd(accum[base + 5u], uint(nq.y));
    atomicAdd(accum[base + 6u], uint(nq.z));
}
