#version 460
// Pass `voxel-surface` (docs/algorithm.md section 5.8): each mesh instance
// drawn three times (gl_InstanceIndex: the axis it is projected along) with
// an orthographic projection of the grid's cube onto the face across that
// axis, GRID_SAMPLES fragments per cell side, so that every triangle is
// rasterized along its dominant axis (voxel_grid/surface.frag keeps those
// fragments) and each fragment stands for the piece of it over one sample.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(push_constant) uniform Push { DrawPush draw; };

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec3 out_grid;  // the position in cells of the grid (0 .. N per axis)
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 3) flat out int out_axis;

void main() {
    InstanceTransform t = transforms[draw.instance];
    vec3 world = (t.world_from_object * vec4(in_position, 1.0)).xyz;
    vec3 g = (world - u.grid_cube.xyz) / u.grid_cube.w;
    int axis = gl_InstanceIndex;
    float n = float(run.grid_side);
    // The two other axes span the image, the projected axis is the depth.
    vec2 across = axis == 0 ? g.yz : (axis == 1 ? g.zx : g.xy);
    gl_Position = vec4(across / n * 2.0 - 1.0, clamp(g[axis] / n, 0.0, 1.0), 1.0);
    out_grid = g;
    out_normal = mat3(t.normal_from_object) * in_normal;
    out_uv = in_uv;
    out_axis = axis;
}
