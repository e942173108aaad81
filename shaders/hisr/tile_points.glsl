// HISR's tile-shared visibility (docs/algorithm.md section 5, "Tile-shared
// visibility"): whether a receiver trusts the visibility marched from one
// of its tile's points (a corner, or a point hisr/visibility.comp chose
// where the corners leave pixels uncovered). hisr/visibility.comp chooses
// the points with the same test the gather weighs them by, so a pixel it
// counts as covered is one the gather interpolates. Needs frame.glsl.
#ifndef TILE_POINTS_GLSL
#define TILE_POINTS_GLSL

// The distance (in cells) from a point within which a receiver trusts its
// visibility fully; at twice it, not at all.
const float SHARED_REACH = 4.0;

// The weight, in [0, 1], of the point at xk (normal nk) for the receiver at
// xi (unit normal n): on its tangent plane within 0.5-1 cell, normals'
// cosine above 0.8-0.9, and within 4-8 cells, each falling off smoothly. A
// point far from the receiver, though on its plane (a floor seen at a
// grazing angle, a tile's corners under a disc and its receivers beyond
// the umbra), sees other occluders.
float tile_point_weight(vec3 xi, vec3 n, vec3 xk, vec3 nk) {
    float cell = u.grid_cube.w;
    float plane = abs(dot(nk, xi - xk)) / cell;
    float apart = length(xi - xk) / cell;
    return (1.0 - smoothstep(0.5, 1.0, plane)) * smoothstep(0.8, 0.9, dot(n, nk))
         * (1.0 - smoothstep(SHARED_REACH, 2.0 * SHARED_REACH, apart));
}

// Widens [lo, hi] by v as the gather reads it (8 bits): the spread of a
// tile's points' visibilities of one entry.
void widen_spread(inout float lo, inout float hi, float v) {
    float q = round(v * 255.0) / 255.0;
    lo = min(lo, q);
    hi = max(hi, q);
}

// Tile points past the corners, per finest tile (HisrCutHeader::points).
const int TILE_POINTS = 4;
const uint TILE_POINT_NONE = 0xffffffffu;

#endif
