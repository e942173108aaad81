#version 460
#extension GL_GOOGLE_include_directive : require
// G-buffer from the camera (docs/algorithm.md section 3, step 1).
#include "frame.glsl"

layout(push_constant) uniform Push { DrawPush draw; };
#include "material.glsl"

layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;

layout(location = 0) out vec4 out_position;  // xyz: world (m); w: view depth (m), 0 = background
layout(location = 1) out vec4 out_normal;    // xyz: unit world normal facing the camera; w: view depth again,
                                             // times u.normal_depth_scale (16-bit, for multires/geometry_level_one.frag)
layout(location = 2) out vec4 out_albedo;    // rgb: linear diffuse albedo

void main() {
    float view_depth = dot(in_world - u.camera_position, u.camera_forward);
    // Positive where there is geometry (0 is background), at any scale.
    float depth = max(view_depth, 1e-30);
    out_position = vec4(in_world, depth);
    out_normal = vec4(facing_normal(in_normal), depth * u.normal_depth_scale);
    out_albedo = vec4(material_albedo(draw.material, in_uv), 1.0);
}
