// The N regular VPLs of docs/algorithm.md section 4: the sqrt(N) x sqrt(N) level k
// of the RSM quadtree (patch means), or with POINT_VPLS the texel at
// each patch's centre with flux and area scaled by the 4^k texels it stands
// for. Include after declaring `u` and the samplers rsm_position, rsm_normal
// and rsm_flux (quadtree mip chains).
#ifndef REGULAR_VPLS_GLSL
#define REGULAR_VPLS_GLSL

// The run's VPLs (regular_vpls::RegularVpls::specialization): the RSM
// quadtree level k they are, VPL_SIDE x VPL_SIDE of them, and whether each
// is its patch's centre texel (--vpl-sampling point).
layout(constant_id = 60) const int VPL_LEVEL = 0;
layout(constant_id = 61) const int VPL_SIDE = 1;
layout(constant_id = 62) const bool POINT_VPLS = false;

int regular_vpl_count() { return VPL_SIDE * VPL_SIDE; }

// VPL j in row-major order; false when its patch saw nothing lit. nrm.w:
// its level as the lists keep it (patch_level in shared.glsl).
bool regular_vpl(int j, out vec4 pos, out vec4 nrm, out vec3 flux) {
    int k = VPL_LEVEL;
    int side = VPL_SIDE;
    ivec2 xy = ivec2(j % side, j / side);
    if (POINT_VPLS) {
        int span = 1 << k;  // RSM texels per VPL side
        ivec2 t = xy * span + span / 2;
        float texels = float(span * span);
        pos = texelFetch(rsm_position, t, 0);
        nrm = texelFetch(rsm_normal, t, 0);
        flux = texelFetch(rsm_flux, t, 0).rgb * texels;
        pos.w *= texels;
    } else {
        pos = texelFetch(rsm_position, xy, k);
        nrm = texelFetch(rsm_normal, xy, k);
        flux = texelFetch(rsm_flux, xy, k).rgb;
    }
    nrm.w = patch_level(k, nrm.w);
    return pos.w > 0.0;
}

#endif
