#version 460
#extension GL_GOOGLE_include_directive : require
// Transforms scene vertices for the RSM (VIEW_FROM_LIGHT = 1) or the G-buffer (0).
#include "shared.glsl"

layout(constant_id = 1) const int VIEW_FROM_LIGHT = 0;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms u; };
layout(push_constant) uniform Push { DrawPush draw; };

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;

void main() {
    vec4 world = draw.world_from_object * vec4(in_position, 1.0);
    // Normals transform by the inverse transpose (non-uniform scale in glTF nodes).
    mat3 normal_matrix = transpose(inverse(mat3(draw.world_from_object)));
    out_world = world.xyz;
    out_normal = normal_matrix * in_normal;
    out_uv = in_uv;
    gl_Position = (VIEW_FROM_LIGHT != 0 ? u.light_view_proj : u.camera_view_proj) * world;
}
