#version 460
// Pass `voxel-surface` (docs/algorithm.md section 5.8): each fragment of a
// triangle rasterized along its dominant axis adds the piece of the
// triangle over its sample to the cell it lies in: its area (a sample's
// square, (cell / GRID_SAMPLES)^2, over the cosine between the triangle and
// the image plane), albedo, normal and place, as fixed-point integer sums
// (voxel_grid/surface.glsl). A triangle covers each sample centre with the
// probability its projected area gives, so its area is counted without bias
// whatever its size; its other two projections are discarded, so it is
// counted once.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "voxel_grid/surface.glsl"

layout(push_constant) uniform Push { DrawPush draw; };
#include "material.glsl"

// Fragments (samples) per cell side of the image.
layout(constant_id = 23) const int GRID_SAMPLES = 4;

layout(set = 2, binding = 0, std430) buffer GridSurface { uint surface[]; };

layout(location = 0) in vec3 in_grid;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) flat in int in_axis;

void main() {
    // The triangle's own plane: the derivatives of a position on it span it
    // (the interpolated normal may bend with smoothing; the area may not).
    vec3 face = cross(dFdx(in_grid), dFdy(in_grid));
    vec3 a = abs(face);
    int dominant = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
    float len = length(face);
    if (dominant != in_axis || len <= 0.0) discard;
    vec3 n = face / len;
    // Front-facing as the mesh winds it: toward its shading normal.
    if (dot(n, in_normal) < 0.0) n = -n;
    ivec3 cell = ivec3(floor(in_grid));
    int side = run.grid_side;
    if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, ivec3(side)))) discard;
    // In units of a cell face: one sample's square over the cosine.
    float area = 1.0 / (float(GRID_SAMPLES * GRID_SAMPLES) * a[in_axis] / len);
    vec3 albedo = material_albedo(draw.material, in_uv);
    vec3 offset = clamp(in_grid - vec3(cell), 0.0, 1.0);
    uint base = SURFACE_WORDS * uint(cell.x + side * (cell.y + side * cell.z));
    float w = area * SURFACE_ONE;
    atomicAdd(surface[base], uint(round(w)));
    for (int k = 0; k < 3; ++k) {
        atomicAdd(surface[base + 1u + uint(k)], uint(round(w * albedo[k])));
        atomicAdd(surface[base + 4u + uint(k)], uint(int(round(w * n[k]))));
        atomicAdd(surface[base + 7u + uint(k)], uint(round(w * offset[k])));
    }
}
