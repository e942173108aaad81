#version 460
// Pass `bounce-cells` (docs/algorithm.md section 5.9): one workgroup per
// coarse cell. Its threads sum the surface of the finest cells under it
// (voxel_grid/surface.glsl) into the cell's area, albedo, normal and
// centroid, then gather the first bounce's irradiance E at the centroid from
// the regular VPLs of this light view (the patch formula, with the methods'
// visibility), and the cell re-emits its power P1 = rho E A (shared notes,
// section 11). Both sums are fixed-order tree reductions: the same every run.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"
#include "voxel_grid/surface.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 64) in;

layout(set = 1, binding = 0, std430) readonly buffer GridSurface { uint surface[]; };
layout(set = 1, binding = 1, std430) writeonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 2, std430) writeonly buffer BouncePower { vec4 power[]; };
layout(set = 1, binding = 3, std430) writeonly buffer BouncePowerSum { vec4 power_sum[]; };
layout(set = 1, binding = 4) uniform sampler2D rsm_position;  // quadtree (mip chain)
layout(set = 1, binding = 5) uniform sampler2D rsm_normal;
layout(set = 1, binding = 6) uniform sampler2D rsm_flux;
#include "regular_vpls/regular_vpls.glsl"

shared vec4 sum_a[64];
shared vec4 sum_b[64];
shared vec4 sum_c[64];

// Sums sum_a, sum_b, sum_c over the workgroup into their entry 0.
void reduce() {
    uint t = gl_LocalInvocationIndex;
    for (uint stride = 32u; stride > 0u; stride >>= 1u) {
        barrier();
        if (t < stride) {
            sum_a[t] += sum_a[t + stride];
            sum_b[t] += sum_b[t + stride];
            sum_c[t] += sum_c[t + stride];
        }
    }
    barrier();
}

void main() {
    uint c = gl_WorkGroupID.x;
    uint t = gl_LocalInvocationIndex;
    int side = run.grid_side;
    int per = side / BOUNCE_SIDE;  // finest cells per coarse side
    ivec3 cc = ivec3(int(c) % BOUNCE_SIDE, (int(c) / BOUNCE_SIDE) % BOUNCE_SIDE,
                     int(c) / (BOUNCE_SIDE * BOUNCE_SIDE));
    // Fixed-point sums, in finest-cell units: area, albedo x area, normal x
    // area, place x area.
    float area = 0.0;
    vec3 rho = vec3(0.0), nrm = vec3(0.0), place = vec3(0.0);
    for (int k = int(t); k < per * per * per; k += 64) {
        ivec3 f = cc * per + ivec3(k % per, (k / per) % per, k / (per * per));
        uint base = SURFACE_WORDS * uint(f.x + side * (f.y + side * f.z));
        float a = float(surface[base]);
        area += a;
        rho += vec3(surface[base + 1u], surface[base + 2u], surface[base + 3u]);
        nrm += vec3(int(surface[base + 4u]), int(surface[base + 5u]), int(surface[base + 6u]));
        place += vec3(surface[base + 7u], surface[base + 8u], surface[base + 9u]) + vec3(f) * a;
    }
    sum_a[t] = vec4(place, area);
    sum_b[t] = vec4(rho, 0.0);
    sum_c[t] = vec4(nrm, 0.0);
    reduce();
    area = sum_a[0].w;
    vec4 g = u.grid_cube;
    vec3 x = g.xyz + sum_a[0].xyz / max(area, 1e-30) * g.w;
    vec3 albedo = sum_b[0].rgb / max(area, 1e-30);
    vec3 mean_n = sum_c[0].xyz / max(area, 1e-30);
    float len = length(mean_n);
    vec3 n = len > 0.0 ? mean_n / len : vec3(0.0, 1.0, 0.0);
    float world_area = area / SURFACE_ONE * g.w * g.w;
    // The first bounce at the centroid, the VPLs shared among the threads.
    vec3 e = vec3(0.0);
    if (area > 0.0) {
        for (int j = int(t); j < regular_vpl_count(); j += 64) {
            vec4 pos, vn;
            vec3 flux;
            if (regular_vpl(j, pos, vn, flux)) e += patch_irradiance(x, n, pos.xyz, vn.xyz, flux, pos.w, int(vn.w));
        }
    }
    barrier();
    sum_a[t] = vec4(e, 0.0);
    sum_b[t] = vec4(0.0);
    sum_c[t] = vec4(0.0);
    reduce();
    if (t == 0u) {
        uint i = uint(BOUNCE_CELL_VEC4S) * c;
        cells[i] = vec4(x, world_area);
        cells[i + 1u] = vec4(n, len);
        cells[i + 2u] = vec4(albedo, 0.0);
        vec4 p = vec4(albedo * sum_a[0].rgb * world_area, 0.0);
        power[c] = p;
        power_sum[c] = p;
    }
}
