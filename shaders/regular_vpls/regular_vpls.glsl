// The N regular VPLs of docs/algorithm.md section 4: the sqrt(N) x sqrt(N) level k
// of the RSM quadtree (patch means), or with HIERARCHY_POINT_VPLS the texel at
// each patch's centre with flux and area scaled by the 4^k texels it stands
// for. Include after declaring `u` and the samplers rsm_position, rsm_normal
// and rsm_flux (quadtree mip chains).
#ifndef REGULAR_VPLS_GLSL
#define REGULAR_VPLS_GLSL

int regular_vpl_count() { return run.vpl_side * run.vpl_side; }

// VPL j in row-major order; false when its patch saw nothing lit. nrm.w:
// its level as the lists keep it (patch_level in shared.glsl).
bool regular_vpl(int j, out vec4 pos, out vec4 nrm, out vec3 flux) {
    int k = run.vpl_level;
    int side = run.vpl_side;
    ivec2 xy = ivec2(j % side, j / side);
    if ((run.hierarchy_flags & HIERARCHY_POINT_VPLS) != 0) {
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
