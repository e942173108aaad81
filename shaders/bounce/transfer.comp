#version 460
// Pass `bounce-transfer` (docs/algorithm.md section 5.9): one invocation per
// pair of coarse cells (i receives, j sends): the visibility V_ij with the
// methods' visibility (vpl.glsl), marched between the two cells' largest
// faces with both ends skipped like a patch's, kept for every later bounce
// of the frame; the faces' kernels are evaluated where the light is
// propagated (bounce-propagate). A cell's faces see each other unoccluded.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "lighting.glsl"
#include "vpl.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, std430) readonly buffer BounceCells { vec4 cells[]; };
layout(set = 1, binding = 1, std430) writeonly buffer BounceTransfer { float transfer[]; };

// The largest face of cell c (its index in `cells`): where the cell's
// visibility is marched from.
int largest_face(int c) {
    int best = bounce_face(c, 0);
    for (int f = 1; f < BOUNCE_FACES; ++f) {
        int i = bounce_face(c, f);
        if (cells[i].w > cells[best].w) best = i;
    }
    return best;
}

void main() {
    uint i = gl_GlobalInvocationID.x, j = gl_GlobalInvocationID.y;
    if (i >= uint(BOUNCE_CELLS) || j >= uint(BOUNCE_CELLS)) return;
    vec4 xi = cells[BOUNCE_CELL_VEC4S * i], xj = cells[BOUNCE_CELL_VEC4S * j];
    float v = 0.0;
    if (xi.w > 0.0 && xj.w > 0.0) {
        v = 1.0;
        if (VOXEL_VISIBILITY && i != j) {
            int fi = largest_face(int(i)), fj = largest_face(int(j));
            vec4 a = cells[fi], b = cells[fj];
            vec3 na = cells[fi + 1].xyz, nb = cells[fj + 1].xyz;
            v = voxel_march(a.xyz, b.xyz, 1.0 - voxel_patch_skip(b.xyz, a.xyz, na, a.w),
                            voxel_patch_skip(a.xyz, b.xyz, nb, b.w));
        }
    }
    transfer[i * uint(BOUNCE_CELLS) + j] = v;
}
