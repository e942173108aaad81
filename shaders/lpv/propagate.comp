#version 460
#extension GL_GOOGLE_include_directive : require
// Method lpv, pass lpv-propagate (docs/algorithm.md section 8.4): one
// iteration of the six-neighbour scheme of Kaplanyan & Dachsbacher (2010),
// gathered: one invocation per cell (all cascades at once). Each of the six
// neighbours s sends light into this cell d through their shared face. Seen
// from the centre of s, the faces of d other than that one (the far face
// and four side faces) subtend 0.40067 and 0.42343 sr; the 30 such faces of
// the six neighbours of s tile the sphere exactly. The flux towards face f
// is its solid angle times the intensity of s toward the face's centre,
//   Phi_f = dw_f * max(0, I_s(w_f)) * (1 - B(w_f)),
// B the blocking potential at the shared face (the mean of its four corner
// geometry cells; the larger of the light's and the camera's), and it
// leaves d as a Lambertian emitter facing out of face f:
//   I_d += Phi_f / pi * max(0, n_f . w).
// Writes the iteration's cells and adds them to the sum.
//
// Each neighbour is one call with constant directions (a loop indexing
// vectors by variable cost lavapipe twice the time).
#include "frame.glsl"
#include "lpv/lpv.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(constant_id = 42) const bool OCCLUSION = true;

// Three planes of LPV_CELLS cells: the red, green and blue SH.
layout(set = 1, binding = 0, std430) readonly buffer LpvSource { vec4 source[]; };
layout(set = 1, binding = 1, std430) writeonly buffer LpvDestination { vec4 destination[]; };
layout(set = 1, binding = 2, std430) buffer LpvSum { vec4 sum[]; };
// Two planes: blocking SH from the RSM's surfels, and from the G-buffer's.
layout(set = 1, binding = 3, std430) readonly buffer LpvGeometry { vec4 geometry[]; };

const float FRONT_SOLID_ANGLE = 0.4006696846462392;
const float SIDE_SOLID_ANGLE = 0.42343135443673896;
// The side faces' directions: (d + e / 2) / |d + e / 2|.
const float SIDE_ALONG = 0.8944271909999159;   // 1 / sqrt(1.25)
const float SIDE_ACROSS = 0.4472135954999579;  // 0.5 / sqrt(1.25)

int c;
ivec3 cell;
vec4 red, green, blue;
// The geometry cells at this cell's eight corners, corner i at offset
// (i & 1, (i >> 1) & 1, i >> 2); the light's, then the eye's.
vec4 corner_light[8];
vec4 corner_eye[8];

// Adds what intensities (sr, sg, sb) send through a face (normal nf) in
// direction w with solid angle omega, past blocking (bl, be).
void face(vec4 sr, vec4 sg, vec4 sb, vec4 bl, vec4 be, vec3 w, vec3 nf, float omega) {
    float t = omega / PI;
    if (OCCLUSION) t *= 1.0 - clamp(max(sh_eval(bl, -w), sh_eval(be, -w)), 0.0, 1.0);
    vec4 lobe = sh_cosine_lobe(nf) * t;
    red += max(0.0, sh_eval(sr, w)) * lobe;
    green += max(0.0, sh_eval(sg, w)) * lobe;
    blue += max(0.0, sh_eval(sb, w)) * lobe;
}

// The neighbour at cell - d sends light along d (a unit axis vector; e1, e2
// the other two axes) through the face with corners k0..k3.
void neighbour(ivec3 d, vec3 e1, vec3 e2, int k0, int k1, int k2, int k3) {
    ivec3 from = cell - d;
    if (!lpv_inside(from)) return;
    int j = lpv_cell_index(c, from);
    vec4 sr = source[j];
    vec4 sg = source[LPV_CELLS + j];
    vec4 sb = source[2 * LPV_CELLS + j];
    vec4 bl = vec4(0.0), be = vec4(0.0);
    if (OCCLUSION) {
        bl = 0.25 * (corner_light[k0] + corner_light[k1] + corner_light[k2] + corner_light[k3]);
        be = 0.25 * (corner_eye[k0] + corner_eye[k1] + corner_eye[k2] + corner_eye[k3]);
    }
    vec3 a = vec3(d);
    face(sr, sg, sb, bl, be, a, a, FRONT_SOLID_ANGLE);
    face(sr, sg, sb, bl, be, SIDE_ALONG * a + SIDE_ACROSS * e1, e1, SIDE_SOLID_ANGLE);
    face(sr, sg, sb, bl, be, SIDE_ALONG * a - SIDE_ACROSS * e1, -e1, SIDE_SOLID_ANGLE);
    face(sr, sg, sb, bl, be, SIDE_ALONG * a + SIDE_ACROSS * e2, e2, SIDE_SOLID_ANGLE);
    face(sr, sg, sb, bl, be, SIDE_ALONG * a - SIDE_ACROSS * e2, -e2, SIDE_SOLID_ANGLE);
}

void main() {
    ivec2 id = ivec2(gl_GlobalInvocationID.xy);
    if (id.x >= LPV_SIZE || id.y >= LPV_SIZE * LPV_SIZE * LPV_CASCADES) return;
    int layer = id.y / LPV_SIZE;
    c = layer / LPV_SIZE;
    cell = ivec3(id.x, id.y % LPV_SIZE, layer % LPV_SIZE);
    if (OCCLUSION) {
        // Corner N of the grid, past its last geometry cell, reads the last.
        for (int i = 0; i < 8; ++i) {
            ivec3 k = min(cell + ivec3(i & 1, (i >> 1) & 1, i >> 2), ivec3(LPV_SIZE - 1));
            int g = lpv_cell_index(c, k);
            corner_light[i] = geometry[g];
            corner_eye[i] = geometry[LPV_CELLS + g];
        }
    }
    red = vec4(0.0);
    green = vec4(0.0);
    blue = vec4(0.0);
    const vec3 X = vec3(1, 0, 0), Y = vec3(0, 1, 0), Z = vec3(0, 0, 1);
    // Light moving up an axis enters through this cell's lower face on it
    // (corners with offset 0 along the axis), moving down through the upper.
    neighbour(ivec3(1, 0, 0), Y, Z, 0, 2, 4, 6);
    neighbour(ivec3(-1, 0, 0), Y, Z, 1, 3, 5, 7);
    neighbour(ivec3(0, 1, 0), Z, X, 0, 1, 4, 5);
    neighbour(ivec3(0, -1, 0), Z, X, 2, 3, 6, 7);
    neighbour(ivec3(0, 0, 1), X, Y, 0, 1, 2, 3);
    neighbour(ivec3(0, 0, -1), X, Y, 4, 5, 6, 7);
    int i = lpv_cell_index(c, cell);
    destination[i] = red;
    destination[LPV_CELLS + i] = green;
    destination[2 * LPV_CELLS + i] = blue;
    sum[i] += red;
    sum[LPV_CELLS + i] += green;
    sum[2 * LPV_CELLS + i] += blue;
}
