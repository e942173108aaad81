#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_ARB_shader_viewport_layer_array : require
// Method lpv, pass lpv-geometry (docs/algorithm.md section 8.3): the
// geometry volume. Every surfel (FROM_GBUFFER: one G-buffer pixel in each
// LPV_STRIDE x LPV_STRIDE block, standing for the block; else a texel of
// level LPV_LEVEL of the RSM quadtree) adds its blocking potential to the
// geometry cell at its nearest cell corner: geometry cell k of a cascade
// sits at corner k of its light cells, so a face between two light cells
// reads it at its four corners. A surfel of area A and normal n in cells of
// side h blocks light travelling in direction w with probability
//   B(w) = A / h^2 * max(0, -n.w)
// (only light arriving at its front: the camera and the light each see one
// side of a surface). Stored as the SH of A / h^2 * max(0, n.v), evaluated
// at v = -w, scaled by 1/0.75 so that the 2-band lobe blocks all of A at
// normal incidence (it peaks at 3/4 of the clamped cosine).
#include "frame.glsl"
#include "lpv/lpv.glsl"
#include "lpv/point.glsl"

layout(constant_id = 43) const bool FROM_GBUFFER = false;
layout(constant_id = 44) const int LPV_LEVEL = 0;   // RSM quadtree level of the surfels
layout(constant_id = 45) const int LPV_STRIDE = 1;  // G-buffer pixels per surfel side

layout(set = 1, binding = 0) uniform sampler2D rsm_position;  // quadtree (mip chain)
layout(set = 1, binding = 1) uniform sampler2D rsm_normal;
layout(set = 1, binding = 2) uniform sampler2D gbuffer_position;
layout(set = 1, binding = 3) uniform sampler2D gbuffer_normal;

layout(location = 0) flat out vec4 out_blocking;

// Surfel j: false when it saw nothing.
bool surfel(int j, out vec3 p, out vec3 n, out float area) {
    if (FROM_GBUFFER) {
        int columns = (int(run.output_size.x) + LPV_STRIDE - 1) / LPV_STRIDE;
        ivec2 pixel = ivec2(j % columns, j / columns) * LPV_STRIDE + LPV_STRIDE / 2;
        pixel = min(pixel, ivec2(run.output_size) - 1);
        vec4 pos = texelFetch(gbuffer_position, pixel, 0);
        n = normalize(texelFetch(gbuffer_normal, pixel, 0).xyz);
        p = pos.xyz;
        // A pixel at view depth z spans 2 z / (H f) across its ray (f =
        // 1 / tan(fov_y / 2), the length of the clip matrix's y row); the
        // surface it sees is that over the cosine to the ray, floored at 0.1.
        mat4 m = u.camera_view_proj;
        float f = length(vec3(m[0][1], m[1][1], m[2][1]));
        float side = 2.0 * pos.w * float(LPV_STRIDE) / (float(run.output_size.y) * f);
        float cos_view = abs(dot(n, normalize(p - u.camera_position)));
        area = side * side / max(cos_view, 0.1);
        return pos.w > 0.0;
    }
    int side = int(run.rsm_resolution) >> LPV_LEVEL;
    ivec2 xy = ivec2(j % side, j / side);
    vec4 pos = texelFetch(rsm_position, xy, LPV_LEVEL);
    n = texelFetch(rsm_normal, xy, LPV_LEVEL).xyz;
    p = pos.xyz;
    area = pos.w;
    return area > 0.0;
}

void main() {
    int c = gl_InstanceIndex;
    vec3 p, n;
    float area;
    bool live = surfel(gl_VertexIndex / 3, p, n, area);
    ivec3 corner = ivec3(round(lpv_grid_position(c, p)));
    live = live && lpv_inside(corner);
    gl_Position = live ? lpv_point_corner(corner, gl_VertexIndex % 3) : LPV_NOWHERE;
    gl_Layer = c * LPV_SIZE + clamp(corner.z, 0, LPV_SIZE - 1);
    float h = lpv_cell_size(c);
    out_blocking = (area / (h * h) / 0.75) * sh_cosine_lobe(n);
}
