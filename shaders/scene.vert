#version 460
#extension GL_GOOGLE_include_directive : require
// Transforms scene vertices for the G-buffer (VIEW_FROM_LIGHT = 0), the RSM (1)
// or the direct light's shadow map (2).
#include "frame.glsl"

layout(constant_id = 1) const int VIEW_FROM_LIGHT = 0;

layout(push_constant) uniform Push { DrawPush draw; };

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;

void main() {
    InstanceTransform t = transforms[draw.instance];
    vec4 world = t.world_from_object * vec4(in_position, 1.0);
    out_world = world.xyz;
    // The inverse transpose (non-uniform scale in glTF nodes), computed on the host.
    out_normal = mat3(t.normal_from_object) * in_normal;
    out_uv = in_uv;
    mat4 view_proj = VIEW_FROM_LIGHT == 2   ? u.shadow_view_proj
                     : VIEW_FROM_LIGHT == 1 ? u.light_view_proj
                                            : u.camera_view_proj;
    gl_Position = view_proj * world;
}
