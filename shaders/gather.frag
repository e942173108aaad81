#version 460
// Stenciled gathering (docs/algorithm.md section 3, step 6): one draw over every
// layer of the illumination buffer; the stencil test (EQUAL 1) runs before the
// shader, so only patches are shaded. Each patch sums C_{j->i} / rho_i over its
// light patches at its mean position and normal. Which light patches, is the
// method (docs/algorithm.md section 4), chosen by LIGHT_PATCHES:
//   0  a list: the N regular VPLs (vpl_list.comp, multires-gather) or the
//      patches Basic ISR chose this frame (isr_select.comp, isr)
//   1  a per-fragment traversal of the packed quadtree (light_tree_pack.comp, hisr)
// With the stencil off (a measurement baseline) every texel is shaded and
// non-patches are masked afterwards.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "light_types.glsl"
#include "vpl.glsl"

layout(early_fragment_tests) in;

layout(constant_id = 0) const int LIGHT_PATCHES = 0;

layout(set = 1, binding = 0) uniform sampler2D geo_mean;    // levels 1..L (geo_levels.glsl)
layout(set = 1, binding = 1) uniform sampler2D geo_normal;  // levels 1..L
layout(set = 1, binding = 2) uniform usampler2D geo_flags;  // levels 1..L
// The regular VPLs, Basic ISR's chosen list, or HISR's packed quadtree.
layout(set = 1, binding = 3, std430) readonly buffer ChosenPatches {
    uint patch_count;
    uint pad0, pad1, pad2;
    LightPatch patches[];
};
layout(set = 1, binding = 4) uniform sampler2D gbuffer_position;  // level 0
layout(set = 1, binding = 5) uniform sampler2D gbuffer_normal;
#define GEO_FLAGS
#include "geo_levels.glsl"

layout(location = 0) flat in int level;  // the layer (layered.vert)

layout(location = 0) out vec4 out_irradiance;  // rgb: E (W/m^2); a: 1 = this texel is a patch
layout(location = 1) out float out_evaluations; // light patches evaluated (a count, R32F so splats can add)

vec3 e = vec3(0.0);
uint evaluations = 0u;

void add_patch(vec3 xi, vec3 ni, vec4 pos, vec4 nrm, vec3 flux) {
    e += patch_irradiance(xi, ni, pos.xyz, nrm.xyz, flux, pos.w);
    evaluations += 1u;
}

void patch_list(vec3 xi, vec3 ni) {
    for (uint j = 0u; j < patch_count; ++j) {
        LightPatch lp = patches[j];
        if (lp.position_area.w <= 0.0) continue;  // an empty regular VPL
        add_patch(xi, ni, lp.position_area, lp.normal, lp.flux.rgb);
    }
}

// Hierarchical ISR (docs/algorithm.md section 4): subdivide patch j while its
// contribution to this receiver could exceed tau.
//
// The bound. With rho <= 1 and both cosines <= 1, Phi_j = rho_j I dw_j and
// A_j = dw_j |V_j|^2 / cos_j >= dw_j |V_j|^2 (section 2) give
//   C_{j->i} <= I dw_j / (pi |V_ij|^2 + dw_j |V_j|^2).
// The talk takes one texel's solid angle as dw = 2 pi / (3 R^2) and scales by
// |V_j|^2, which makes the bound independent of the light's distance and
// gives its form: C <= 2 I |V_j|^2 / (3 R^2 |V_ij|^2 + 2 |V_j|^2). Requiring
// it to exceed tau:
//   subdivide j  iff  |V_ij|^2 <= T |V_j|^2,  T = 2 (I - tau) / (3 tau R^2),
// constant per frame (light_tree.x; `--tau` is tau / I, so T = 2 (1 - tau) /
// (3 tau R^2)). The per-level factor: a patch k levels above the finest stands
// for 4^k texels, i.e. one texel of an (R / 2^k)^2 RSM, so R^2 becomes
// R^2 / 4^k and its threshold 4^k T. For cube faces and orthographic RSMs
// the right-hand side differs: hisr_bound in light_types.glsl derives it.
//
// Invalid patches (spanning a discontinuity) are held to a tighter test: the
// bound above drops both cosines, so it holds for them too, but their mean
// position and normal can misplace their whole contribution, where a valid
// patch's misplace only a small part of it. An invalid patch is split while
// its bound could exceed tau * HISR_INVALID_TAU_SCALE, i.e. against the
// threshold T / HISR_INVALID_TAU_SCALE (for small tau). Splitting them always
// costs about 520 evaluations per fragment in the Cornell box whatever tau
// is; docs/algorithm.md section 4.3 has the measurements behind the scale.
//
// Depth-first with a fixed stack and no recursion; children are pushed only
// above the max depth and when they fit, so every read is inside the tree
// (a full stack evaluates the patch instead of splitting it). Depth d holds
// 2^d x 2^d patches and the tree is at most 12 deep (RSM 4096), so the stack
// holds at most 3 per depth plus the root: 40 entries.
//
// The nodes come from the packed tree (light_tree_pack.comp, bound as
// ChosenPatches): node (x, y) of depth d is patches[(4^d - 1) / 3 + y 2^d + x].
const int STACK_SIZE = 40;

int node_index(ivec3 node) { return ((1 << (2 * node.z)) - 1) / 3 + node.y * (1 << node.z) + node.x; }

void traverse(vec3 xi, vec3 ni) {
    int top = run.light_levels.w;  // mip of the single root patch
    int start = run.light_levels.x;
    int max_depth = run.light_levels.y;
    float t_finest = run.light_tree.x;
    ivec3 stack[STACK_SIZE];  // xy: patch coordinates; z: depth (2^z x 2^z patches at that depth)
    int side = 1 << start;
    for (int s = 0; s < side * side; ++s) {
        int sp = 0;
        stack[sp++] = ivec3(s % side, s / side, start);
        while (sp > 0) {
            ivec3 node = stack[--sp];
            LightPatch lp = patches[node_index(node)];
            if (lp.position_area.w <= 0.0) continue;  // saw nothing
            bool split = false;
            if (node.z < max_depth && sp + 4 <= STACK_SIZE) {
                int mip = top - node.z;
                vec3 vij = lp.position_area.xyz - xi;
                float reach = exp2(float(2 * mip)) * hisr_bound(lp.position_area.xyz, node, t_finest);
                if (lp.normal.w == PATCH_INVALID) reach /= HISR_INVALID_TAU_SCALE;
                split = dot(vij, vij) <= reach;
            }
            if (split) {
                for (int i = 3; i >= 0; --i) stack[sp++] = ivec3(2 * node.xy + ivec2(i & 1, i >> 1), node.z + 1);
            } else {
                add_patch(xi, ni, lp.position_area, lp.normal, lp.flux.rgb);
            }
        }
    }
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 xi = geo_mean_at(p, level).xyz;
    vec3 ni = geo_normal_at(p, level).xyz;
    if (LIGHT_PATCHES == 0) {
        patch_list(xi, ni);
    } else {
        traverse(xi, ni);
    }
    float is = 1.0;
    if ((run.hierarchy.w & HIERARCHY_STENCIL_OFF) != 0 && !is_patch(level, run.hierarchy.x, p)) {
        is = 0.0;
        e = vec3(0.0);
        evaluations = 0u;
    }
    out_irradiance = vec4(e, is);
    out_evaluations = float(evaluations);
}
