// Diffuse albedo of a scene fragment: baseColorFactor times baseColorTexture
// (docs/algorithm.md section 3, step 1).
#ifndef MATERIAL_GLSL
#define MATERIAL_GLSL

// The texture arrays the scene has (1 to 8): the taps of arrays past them
// are left out of the pipeline, as a CPU driver (lavapipe) runs every
// branch of the choice below for every fragment.
layout(constant_id = 0) const int TEXTURE_ARRAYS = 8;

layout(set = 1, binding = 0, std430) readonly buffer Materials { MaterialGpu materials[]; };

// The scene's textures, grouped by size into up to 8 2D array images
// (src/frame/texture_arrays). Each array is a binding of its own, picked by
// constant indices: indexing an array of bindings by a value computed here
// would need shaderSampledImageArrayDynamicIndexing, which not every device
// has (lavapipe in Mesa 22 lacks it).
layout(set = 1, binding = 1) uniform sampler2DArray texture_array_0;
layout(set = 1, binding = 2) uniform sampler2DArray texture_array_1;
layout(set = 1, binding = 3) uniform sampler2DArray texture_array_2;
layout(set = 1, binding = 4) uniform sampler2DArray texture_array_3;
layout(set = 1, binding = 5) uniform sampler2DArray texture_array_4;
layout(set = 1, binding = 6) uniform sampler2DArray texture_array_5;
layout(set = 1, binding = 7) uniform sampler2DArray texture_array_6;
layout(set = 1, binding = 8) uniform sampler2DArray texture_array_7;

// Array a at p (u, v, layer) through the scene's sampler: bilinear, with
// repeat at the layer's edges. textureLod: implicit derivatives are
// undefined in divergent branches, and the arrays have one mip.
vec3 array_sample(int a, vec3 p) {
    if (TEXTURE_ARRAYS <= 1 || a == 0) return textureLod(texture_array_0, p, 0.0).rgb;
    if (TEXTURE_ARRAYS <= 2 || a == 1) return textureLod(texture_array_1, p, 0.0).rgb;
    if (TEXTURE_ARRAYS <= 3 || a == 2) return textureLod(texture_array_2, p, 0.0).rgb;
    if (TEXTURE_ARRAYS <= 4 || a == 3) return textureLod(texture_array_3, p, 0.0).rgb;
    if (TEXTURE_ARRAYS <= 5 || a == 4) return textureLod(texture_array_4, p, 0.0).rgb;
    if (TEXTURE_ARRAYS <= 6 || a == 5) return textureLod(texture_array_5, p, 0.0).rgb;
    if (TEXTURE_ARRAYS <= 7 || a == 6) return textureLod(texture_array_6, p, 0.0).rgb;
    return textureLod(texture_array_7, p, 0.0).rgb;
}

// The material's texture at uv: bilinear with repeat on linear values (the
// sRGB format decodes before filtering), texel centres at (i + 0.5) / size
// (docs/algorithm.md section 3, step 1), as the path tracer samples it. A
// texture that fills its layer has scale 1 and offset 0, and the sampler
// repeats it; a bordered one (frame/texture_arrays) sits inside its layer,
// and its border repeats it at the taps across its edges.
vec3 texture_albedo(MaterialGpu m, vec2 uv) {
    vec2 p = fract(uv) * m.texture_scale + m.texture_offset;
    return array_sample(m.texture_array, vec3(p, float(m.texture_layer)));
}

vec3 material_albedo(uint material, vec2 uv) {
    MaterialGpu m = materials[material];
    vec3 albedo = m.base_color.rgb;
    if (m.texture_array >= 0) {
        albedo *= texture_albedo(m, uv);
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
