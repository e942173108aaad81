#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_ARB_shader_viewport_layer_array : require
// A point light's cube RSM in one layered draw (docs/algorithm.md section 2.4):
// every scene draw is instanced six times, instance f rasterizing into layer f
// (cube face f: +x, -x, +y, -y, +z, -z) through that face's 90 degree
// projection. The fragment shader is rsm_cube.frag, told the face.
#include "frame.glsl"

layout(push_constant) uniform Push { DrawPush draw; };

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 3) flat out int out_face;

void main() {
    InstanceTransform t = transforms[draw.instance];
    vec4 world = t.world_from_object * vec4(in_position, 1.0);
    out_world = world.xyz;
    out_normal = mat3(t.normal_from_object) * in_normal;
    out_uv = in_uv;
    out_face = gl_InstanceIndex;
    gl_Layer = gl_InstanceIndex;
    gl_Position = u.cube_view_proj[gl_InstanceIndex] * world;
}
