#version 460
// Pass `bounce-cells` (docs/algorithm.md section 5.9): one workgroup per
// coarse cell. Its threads split the surface of the finest cells under it
// (voxel_grid/surface.glsl) among the cell's six faces by facing
// (bounce/bounce.glsl) and sum each face's area, albedo, normal and
// centroid; then gather the first bounce's irradiance E at each face's
// centroid from the regular VPLs of this light view (the patch formula with
// the methods' visibility, the face a disc like a patch), and each face
// re-emits its power P1 = rho E A (shared notes, section 11). Every sum is a
// fixed-order tree reduction: the same every run.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"
#include "voxel_grid/surface.glsl"
#include "bounce/bounce.glsl"

// Few threads, so that one shared array holds every sum at once and each
// reduction is one tree (a barrier per level): lavapipe runs barriers slowly.
const uint THREADS = 32u;
layout(local_size_x = THREADS) in;

layout(set = 1, binding = 0, std430) readonly buffer GridSurface { uint surface[]; };
layout(set = 1, binding = 1, std430) writeonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 2, std430) writeonly buffer BouncePower { vec4 power[]; };
layout(set = 1, binding = 3, std430) writeonly buffer BouncePowerSum { vec4 power_sum[]; };
layout(set = 1, binding = 4) uniform sampler2D rsm_position;  // quadtree (mip chain)
layout(set = 1, binding = 5) uniform sampler2D rsm_normal;
layout(set = 1, binding = 6) uniform sampler2D rsm_flux;
#include "regular_vpls/regular_vpls.glsl"

// What each thread sums, REDUCED vec4s per thread: per face its place and
// area, albedo, normal (3 BOUNCE_FACES vec4s); later its first bounce.
const uint REDUCED = 3u * uint(BOUNCE_FACES);
shared vec4 sums[THREADS * REDUCED];
// The faces, once summed: centroid (world) and area (m^2), unit normal,
// albedo.
shared vec4 face_x[BOUNCE_FACES];
shared vec3 face_n[BOUNCE_FACES];
shared vec3 face_rho[BOUNCE_FACES];

// Sums the first n vec4s of every thread's slice of `sums` over the
// workgroup into thread 0's slice: a fixed-order tree.
void reduce(uint n) {
    uint t = gl_LocalInvocationIndex;
    for (uint stride = THREADS / 2u; stride > 0u; stride >>= 1u) {
        barrier();
        if (t < stride) {
            for (uint k = 0u; k < n; ++k) sums[t * REDUCED + k] += sums[(t + stride) * REDUCED + k];
        }
    }
    barrier();
}

// Face f's share of a finest cell whose mean normal is m (|m| <= 1): m_k^2
// where f faces along axis k on m's side, and (1 - |m|^2) / 6 for every face.
float face_weight(vec3 m, int f) {
    float mk = m[f / 2];
    bool along = (f % 2 == 0) ? mk > 0.0 : mk < 0.0;
    return (along ? mk * mk : 0.0) + max(1.0 - dot(m, m), 0.0) / float(BOUNCE_FACES);
}

// The unit normal of face f: its axis, toward its side.
vec3 face_axis(int f) {
    vec3 n = vec3(0.0);
    n[f / 2] = (f % 2 == 0) ? 1.0 : -1.0;
    return n;
}

void main() {
    uint c = gl_WorkGroupID.x;
    uint t = gl_LocalInvocationIndex;
    int side = run.grid_side;
    int per = side / BOUNCE_SIDE;  // finest cells per coarse side
    ivec3 cc = ivec3(int(c) % BOUNCE_SIDE, (int(c) / BOUNCE_SIDE) % BOUNCE_SIDE,
                     int(c) / (BOUNCE_SIDE * BOUNCE_SIDE));
    // Per face, in finest-cell units: area, albedo x area, normal x area,
    // place x area.
    float area[BOUNCE_FACES];
    vec3 rho[BOUNCE_FACES], nrm[BOUNCE_FACES], place[BOUNCE_FACES];
    for (int f = 0; f < BOUNCE_FACES; ++f) {
        area[f] = 0.0;
        rho[f] = nrm[f] = place[f] = vec3(0.0);
    }
    for (int k = int(t); k < per * per * per; k += int(THREADS)) {
        ivec3 g = cc * per + ivec3(k % per, (k / per) % per, k / (per * per));
        uint base = SURFACE_WORDS * uint(g.x + side * (g.y + side * g.z));
        float a = float(surface[base]);
        if (a <= 0.0) continue;
        vec3 r = vec3(surface[base + 1u], surface[base + 2u], surface[base + 3u]);
        vec3 m = vec3(int(surface[base + 4u]), int(surface[base + 5u]), int(surface[base + 6u])) / a;
        float len = length(m);
        vec3 unit = len > 0.0 ? m / len : vec3(0.0);
        float folded = max(1.0 - dot(m, m), 0.0) / float(BOUNCE_FACES);
        vec3 x = vec3(surface[base + 7u], surface[base + 8u], surface[base + 9u]) + vec3(g) * a;
        // Unrolled by hand: six faces, no loop for lavapipe's count.
#define BOUNCE_ADD_FACE(f)                                                      \
        {                                                                       \
            float w = face_weight(m, f);                                        \
            area[f] += a * w;                                                   \
            rho[f] += r * w;                                                    \
            nrm[f] += a * ((w - folded) * unit + folded * face_axis(f));        \
            place[f] += x * w;                                              \
        }
        BOUNCE_ADD_FACE(0) BOUNCE_ADD_FACE(1) BOUNCE_ADD_FACE(2)
        BOUNCE_ADD_FACE(3) BOUNCE_ADD_FACE(4) BOUNCE_ADD_FACE(5)
#undef BOUNCE_ADD_FACE
    }
    vec4 g = u.grid_cube;
    for (int f = 0; f < BOUNCE_FACES; ++f) {
        sums[t * REDUCED + 3u * uint(f)] = vec4(place[f], area[f]);
        sums[t * REDUCED + 3u * uint(f) + 1u] = vec4(rho[f], 0.0);
        sums[t * REDUCED + 3u * uint(f) + 2u] = vec4(nrm[f], 0.0);
    }
    reduce(REDUCED);
    if (t < uint(BOUNCE_FACES)) {
        uint f = t;
        vec4 xa = sums[3u * f];
        float inv = 1.0 / max(xa.w, 1e-30);
        vec3 n = sums[3u * f + 2u].xyz;
        face_x[f] = vec4(g.xyz + xa.xyz * inv * g.w, xa.w / SURFACE_ONE * g.w * g.w);
        face_n[f] = length(n) > 0.0 ? normalize(n) : face_axis(int(f));
        face_rho[f] = sums[3u * f + 1u].rgb * inv;
    }
    barrier();
    // The first bounce at each face's centroid, the VPLs shared among the
    // threads, marched only where the VPL lights the face at all. The face's end of a march is skipped like a patch's (its
    // disc's radius over its plane): its centroid lies off its surfaces by
    // up to about that.
    vec3 e[BOUNCE_FACES];
    for (int f = 0; f < BOUNCE_FACES; ++f) e[f] = vec3(0.0);
    for (int j = int(t); j < regular_vpl_count(); j += int(THREADS)) {
        vec4 pos, vn;
        vec3 flux;
        if (!regular_vpl(j, pos, vn, flux)) continue;
#define BOUNCE_FIRST(f)                                                                      \
        if (face_x[f].w > 0.0) {                                                             \
            vec3 x = face_x[f].xyz, n = face_n[f];                                           \
            vec3 k = patch_unshadowed(x, n, pos.xyz, vn.xyz, flux, pos.w, int(vn.w));        \
            if (VOXEL_VISIBILITY && k != vec3(0.0)) {                                        \
                float t0 = 1.0 - voxel_patch_skip(pos.xyz, x, n, face_x[f].w);               \
                k *= voxel_march(x, pos.xyz, t0, voxel_patch_skip(x, pos.xyz, vn.xyz, pos.w)); \
            }                                                                                \
            e[f] += k;                                                                       \
        }
        BOUNCE_FIRST(0) BOUNCE_FIRST(1) BOUNCE_FIRST(2)
        BOUNCE_FIRST(3) BOUNCE_FIRST(4) BOUNCE_FIRST(5)
#undef BOUNCE_FIRST
    }
    for (int f = 0; f < BOUNCE_FACES; ++f) sums[t * REDUCED + uint(f)] = vec4(e[f], 0.0);
    reduce(uint(BOUNCE_FACES));
    vec3 irradiance[BOUNCE_FACES];
    for (int f = 0; f < BOUNCE_FACES; ++f) irradiance[f] = sums[f].rgb;
    if (t == 0u) {
        vec4 all_ = vec4(0.0);
        for (int f = 0; f < BOUNCE_FACES; ++f) {
            int i = bounce_face(int(c), f);
            cells[i] = face_x[f];
            cells[i + 1] = vec4(face_n[f], 0.0);
            cells[i + 2] = vec4(face_rho[f], 0.0);
            vec4 p = vec4(face_rho[f] * irradiance[f] * face_x[f].w, 0.0);
            power[BOUNCE_FACES * int(c) + f] = p;
            power_sum[BOUNCE_FACES * int(c) + f] = p;
            all_ += vec4(face_x[f].xyz * face_x[f].w, face_x[f].w);
        }
        cells[BOUNCE_CELL_VEC4S * int(c)] = vec4(all_.xyz / max(all_.w, 1e-30), all_.w);
    }
}
