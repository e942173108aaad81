// Data shared between host and shaders. The host mirrors each struct with a
// #[repr(C)] type in src/gpu_types.rs; tests/layouts.rs checks every size and
// offset against the SPIR-V compiled from this file. Change both together.
#ifndef SHARED_GLSL
#define SHARED_GLSL

// What changes every frame: the camera and the light (std140 uniform block,
// set 0 binding 0, one buffer per frame in flight).
struct FrameUniforms {
    mat4 camera_view_proj;  // world -> camera clip: reversed-Z, infinite far, y down
    mat4 light_view_proj;   // world -> RSM clip: same conventions, square, covers the outer cone
    vec3 camera_position;   // world (m)
    float pad0;
    vec3 camera_forward;    // unit view direction
    float normal_depth_scale; // the G-buffer normal's w holds view depth times this (a
                            // power of two fitted to the scene: it is 16-bit)
    vec3 light_position;    // world (m)
    float light_range;      // m, 0 = no range
    vec3 light_direction;   // unit spot axis, or the directional light's direction
    int light_kind;         // LIGHT_*: what this frame set's RSM is rendered from
    vec3 light_intensity;   // color * intensity, W/sr (candela read as W/sr)
    float light_peak;       // I, the peak of light_intensity (W/sr)
    float cone_scale;       // spot: KHR_lights_punctual lightAngleScale
    float cone_offset;      // spot: KHR_lights_punctual lightAngleOffset
    float rsm_half_extent;  // tan(RSM half field of view) (spot, point), or half the side
                            // of the orthographic RSM (m, directional)
    float rsm_depth_range;  // the orthographic RSM's depth range (m, directional)
    int cube_face;          // a point light's cube face (0..5: +x, -x, +y, -y, +z, -z)
    int light_index;        // the light's index in the scene
    float shadow_half_extent; // as rsm_half_extent, of the shadow map (shadow_view_proj)
    int pad3;
    mat4 cube_view_proj[6]; // point lights: world -> clip of each cube face (+x, -x, +y, -y,
                            // +z, -z), for the one layered draw of all six (rsm_cube.vert)
    vec4 grid_cube;         // the voxel grid's cube around this frame's posed scene:
                            // xyz its min corner (m), w the side of a finest cell (m)
    vec3 scene_min;         // the scene's bounds as loaded (m; relative to the render
    float pad4;             // origin like every position): fixed for a run, so what
    vec3 scene_max;         // is fitted to them does not change size as objects move
    float pad5;
    mat4 shadow_view_proj;  // world -> shadow map clip (direct light's shadows, shadow.rs):
                            // the RSM's frustum for spot and point lights; a directional
                            // light's fitted to what the camera sees (docs/algorithm.md 2.2)
};

// light_kind: what this frame set's RSM is rendered from (docs/algorithm.md section 2.4).
const int LIGHT_SPOT = 0;         // perspective, the square around the outer cone
const int LIGHT_POINT = 1;        // one 90 degree cube face; six make the point light
const int LIGHT_DIRECTIONAL = 2;  // orthographic, fitted to the scene's bounds

// What is fixed for a run and shared by the passes of every method: sizes,
// thresholds, levels (std140 uniform block, set 0 binding 1, written once).
// Each group is filled by the module that owns its parameters
// (src/gpu_types.rs names it), from the one function that derives each
// value. A method's own parameters reach its shaders as specialization
// constants, declared in its shader folder.
struct RunUniforms {
    // Shadows of the direct light.
    float shadow_normal_offset;   // shadow-map texels at the receiver (0 by default)
    float shadow_depth_bias;      // constant, relative to the distance to the light
    float pcf_radius;             // PCF tap spacing (shadow-map texels)
    float shadow_slope_bias;      // shadow-map texels of the receiver plane's depth gradient
    // Sizes.
    uvec2 output_size;            // width, height (pixels)
    uint rsm_resolution;          // R
    int rsm_top_level;            // log2 R: the RSM quadtree's root (one patch)
    float exposure;               // multiplier applied before the PNG's sRGB encoding
    // The eye-space hierarchy (docs/algorithm.md section 3).
    int levels;                   // coarsest level L
    float depth_threshold;        // relative view-depth range, (max - min) / min
    float normal_chord;           // normal threshold as the chord |n_max - n_min| of
                                  // the normals' component box, 2 sin(angle / 2)
    int hierarchy_flags;          // HIERARCHY_*
    // Patch validity in the RSM quadtree (docs/algorithm.md section 4).
    float validity_depth;         // relative to the distance to the light
    float validity_normal_cos;    // cosine of the angle threshold
    int patch_kernel;             // PATCH_KERNEL_*: how a merged light patch is evaluated (vpl.glsl)
    // The voxel grid (docs/algorithm.md section 5.6; src/voxel_grid).
    int grid_side;                // N: finest cells per side (a power of 2)
    int grid_levels;              // levels 0..grid_levels-1, side N >> k (at least 4)
    uint shadow_resolution;       // S: the direct light's shadow map (S x S, docs/algorithm.md 2.2)
    int pad1;
    int pad2;
};

// RunUniforms::patch_kernel (docs/algorithm.md section 2.6): a patch of
// several RSM texels evaluated at its centre with the disc form factor, or
// with the second-order term of its texels' spread added.
const int PATCH_KERNEL_CENTRE = 0;
const int PATCH_KERNEL_SECOND_ORDER = 1;

// Where one mesh instance is this frame (std430, set 0 binding 2, one per
// `Scene::instances` entry, one buffer per frame in flight).
struct InstanceTransform {
    mat4 world_from_object;
    mat4 normal_from_object;  // inverse transpose of the upper 3x3 (non-uniform scale)
};

const float PI = 3.14159265358979323846;

// One light patch: a node of the RSM quadtree, in the lists a light-space
// source writes for the gather (multires::LightSource).
struct LightPatch {
    vec4 position_area;  // xyz: flux-weighted mean position (m; rsm_tree.comp); w: area A (m^2)
    vec4 normal;         // xyz: unit mean normal; w: patch_level in a list, or
                         // PATCH_* in a packed tree
    vec4 flux;           // rgb: summed flux Phi (W); a: summed solid angle (sr), or
                         // what a source keeps there (a packed tree: its squared reach)
};

// RSM quadtree normal.w: what a patch is.
const float PATCH_EMPTY = 0.0;    // saw no geometry
const float PATCH_VALID = 1.0;    // one surface: may stand for all its texels
const float PATCH_INVALID = -1.0; // spans a depth or normal discontinuity (ISR never takes it whole)

// A patch's level as patch_irradiance (vpl.glsl) and the light-patch lists take it: its
// RSM quadtree level k (0: one texel), negated when it spans a discontinuity
// (state PATCH_INVALID), whose texels lie on no one disc.
int patch_level(int k, float state) { return state == PATCH_INVALID ? -k : k; }

// RunUniforms::hierarchy_flags bits.
const int HIERARCHY_STENCIL_OFF = 4;   // gather every texel, mask afterwards

// Geometry-mip flag bits (image geo_flags).
const uint GEO_HAS_GEOMETRY = 1u;  // at least one pixel of the texel sees geometry
const uint GEO_SMOOTH = 2u;        // fully covered, depth range and normal spread under the thresholds
const uint GEO_SPLIT = 4u;         // has geometry and is not a leaf: not smooth, or 2:1 balance

// One material (std430 storage buffer, set 1, binding 0 of scene passes).
struct MaterialGpu {
    vec4 base_color;     // linear RGBA albedo factor
    int texture_array;    // the texture's array (texture_array_N of material.glsl), -1 for none
    int texture_layer;    // its layer in that array
    vec2 texture_scale;   // where in the layer the texture is: sampled at
    vec2 texture_offset;  // fract(uv) * texture_scale + texture_offset
    vec2 pad0;
};

// Push constants of one dispatch of pass visibility-grid (voxel_grid/voxelize.comp):
// a range of one instance's triangles, one invocation each.
struct VoxelizePush {
    uint first_index;     // the instance's mesh's first index
    int vertex_offset;    // added to its indices
    uint instance;        // index into the frame's InstanceTransform array
    uint first_triangle;  // this dispatch's first triangle of the mesh
    uint triangles;       // this dispatch's triangle count
};

// Push constants of one dispatch of pass visibility-grid's OR-levels
// (voxel_grid/levels.comp).
struct GridLevelPush {
    int level;  // the level it reads; it writes level + 1
};

// Push constants of one scene draw.
struct DrawPush {
    uint instance;  // index into the frame's InstanceTransform array
    uint material;  // index into the materials
};

// Push constants of the viewer's present pass (viewer/present.frag): the frame's
// image scaled into the window, aspect kept, the rest letterboxed.
struct PresentPush {
    ivec4 rect;        // xy: the image's top-left corner in the window (pixels); zw: its size
    vec4 letterbox;    // rgb: colour outside the image, display-encoded
    int view;          // PRESENT_VIEW_*: what is shown
    int srgb_target;   // 1: the window's format encodes sRGB itself (write linear values)
    int pad0;
    int pad1;
};

// PresentPush.view.
const int PRESENT_VIEW_FINAL = 0;     // the tonemapped frame (the PNG of `isr render`)
const int PRESENT_VIEW_INDIRECT = 1;  // albedo / pi * E alone, times the exposure
const int PRESENT_VIEW_HOST = 2;      // an sRGB image the host uploaded (levels, vpl-count)

// Push constants of the viewer's text overlay (viewer/overlay_text.vert/.frag): a
// grid of 8x8 glyphs; each cell of the text buffer is `char | colour << 8`.
struct OverlayPush {
    ivec4 rect;    // xy: the grid's top-left corner (pixels); z, w: columns, rows
    ivec4 target;  // x, y: window size (pixels); z: screen pixels per glyph pixel; w: unused
};

#endif
