// Diffuse albedo of a scene fragment: baseColorFactor times baseColorTexture.
#ifndef MATERIAL_GLSL
#define MATERIAL_GLSL

layout(constant_id = 0) const int TEXTURE_COUNT = 1;

layout(set = 1, binding = 0, std430) readonly buffer Materials { MaterialGpu materials[]; };
layout(set = 1, binding = 1) uniform sampler2D textures[TEXTURE_COUNT];

vec3 material_albedo(uint material, vec2 uv) {
    MaterialGpu m = materials[material];
    vec3 albedo = m.base_color.rgb;
    if (m.texture >= 0) {
        albedo *= texture(textures[m.texture], uv).rgb;  // sRGB format: decoded to linear
    }
    return albedo;
}

// Shading normal facing the viewer: back faces of double-sided materials flip
// (single-sided ones are culled, so this never fires for them).
vec3 facing_normal(vec3 n) {
    n = normalize(n);
    return gl_FrontFacing ? n : -n;
}

#endif
