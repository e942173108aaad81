// Data shared between host and shaders. The host mirrors each struct with a
// #[repr(C)] type in src/gpu_types.rs; tests/layouts.rs checks every size and
// offset against the SPIR-V compiled from this file. Change both together.
#ifndef SHARED_GLSL
#define SHARED_GLSL

// Per-frame constants (std140 uniform block, set 0, binding 0 of every pass).
struct FrameUniforms {
    mat4 camera_view_proj;  // world -> camera clip: reversed-Z, infinite far, y down
    mat4 light_view_proj;   // world -> RSM clip: same conventions, square, covers the outer cone
    vec4 camera_position;   // xyz: world (m)
    vec4 camera_forward;    // xyz: unit view direction
    vec4 light_position;    // xyz: world (m); w: range (m), 0 = no range
    vec4 light_direction;   // xyz: unit spot axis
    vec4 light_intensity;   // rgb: color * intensity, W/sr (candela read as W/sr)
    vec4 light_cone;        // x, y: KHR_lights_punctual lightAngleScale, lightAngleOffset;
                            // z: tan(RSM half field of view); w: RSM resolution R
    vec4 shadow;            // x: normal offset (RSM texels); y: constant relative depth bias;
                            // z: PCF tap spacing (texels); w: slope bias (texels along the slope)
    vec4 exposure;          // x: multiplier applied before the PNG's sRGB encoding
    uvec4 size;             // x, y: output width, height; z: RSM resolution
};

// One glTF material (std430 storage buffer, set 0, binding 1 of scene passes).
struct MaterialGpu {
    vec4 base_color;  // linear RGBA albedo factor
    int texture;      // index into the scene texture array, -1 for none
    int pad0;
    int pad1;
    int pad2;
};

// Push constants of one scene draw.
struct DrawPush {
    mat4 world_from_object;
    uint material;
    uint pad0;
    uint pad1;
    uint pad2;
};

#endif
