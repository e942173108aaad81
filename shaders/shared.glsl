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
    vec4 camera_position;   // xyz: world (m)
    vec4 camera_forward;    // xyz: unit view direction
    vec4 light_position;    // xyz: world (m); w: range (m), 0 = no range
    vec4 light_direction;   // xyz: unit spot axis
    vec4 light_intensity;   // rgb: color * intensity, W/sr (candela read as W/sr); w: I, the
                            // peak of rgb (W/sr)
    vec4 light_cone;        // x, y: KHR_lights_punctual lightAngleScale, lightAngleOffset (spot);
                            // z: tan(RSM half field of view) (spot, point), or half the side of
                            // the orthographic RSM (m, directional); w: the orthographic RSM's
                            // depth range (m, directional)
    ivec4 light_kind;       // x: LIGHT_*; y: cube face of a point light (0..5: +x, -x, +y, -y, +z, -z);
                            // z: index of the light in the scene; w: unused
    mat4 cube_view_proj[6]; // point lights: world -> clip of each cube face (+x, -x, +y, -y,
                            // +z, -z), for the one layered draw of all six (rsm_cube.vert)
};

// light_kind.x: what this frame set's RSM is rendered from (docs/algorithm.md section 2.4).
const int LIGHT_SPOT = 0;         // perspective, the square around the outer cone
const int LIGHT_POINT = 1;        // one 90 degree cube face; six make the point light
const int LIGHT_DIRECTIONAL = 2;  // orthographic, fitted to the scene's bounds

// What is fixed for a run: sizes, thresholds, levels (std140 uniform block,
// set 0 binding 1, written once).
struct RunUniforms {
    vec4 shadow;            // x: normal offset (RSM texels); y: constant relative depth bias;
                            // z: PCF tap spacing (texels); w: slope bias (texels along the slope)
    vec4 exposure;          // x: multiplier applied before the PNG's sRGB encoding
    uvec4 size;             // x, y: output width, height; z: RSM resolution R
    vec4 refine;            // multiresolution buffer (docs/algorithm.md section 3): x: depth threshold
                            // (relative depth range, (max - min) / min); y: normal threshold (chord
                            // length |n_max - n_min| of the component box, 2 sin(angle / 2))
    ivec4 hierarchy;        // x: coarsest level L; y: RSM quadtree level k of the VPLs;
                            // z: VPLs per side sqrt(N); w: flags, see HIERARCHY_*
    vec4 light_tree;        // light-space hierarchy (docs/algorithm.md sections 2 and 4): x: HISR's T at
                            // the finest level, 2 (1 - tau) / (3 tau R^2); y: patch validity depth
                            // threshold (relative distance to the light); z: validity normal
                            // threshold (cosine); w: unused
    ivec4 light_levels;     // x: HISR start depth (2^x x 2^x patches); y: HISR max depth;
                            // z: ISR base level (RSM mip); w: log2 R, the top mip (one patch)
    vec4 splat;             // x: restricted-splat threshold (irradiance, W/m^2)
};

// Where one mesh instance is this frame (std430, set 0 binding 2, one per
// `Scene::instances` entry, one buffer per frame in flight).
struct InstanceTransform {
    mat4 world_from_object;
    mat4 normal_from_object;  // inverse transpose of the upper 3x3 (non-uniform scale)
};

const float PI = 3.14159265358979323846;

// One light patch chosen by Basic ISR (a node of the RSM quadtree).
struct LightPatch {
    vec4 position_area;  // xyz: area-weighted mean position (m); w: area A (m^2)
    vec4 normal;         // xyz: unit mean normal; w: RSM quadtree level (ISR's list) or
                         // PATCH_* (HISR's packed tree)
    vec4 flux;           // rgb: summed flux Phi (W); a: summed solid angle (sr), or
                         // the squared reach (hisr_reach, HISR's packed tree)
};

// RSM quadtree normal.w: what a patch is.
const float PATCH_EMPTY = 0.0;    // saw no geometry
const float PATCH_VALID = 1.0;    // one surface: may stand for all its texels
const float PATCH_INVALID = -1.0; // spans a depth or normal discontinuity (ISR never takes it whole)

// HISR splits an invalid patch while its bound could exceed tau times this
// (gather.frag, docs/algorithm.md section 4.3).
const float HISR_INVALID_TAU_SCALE = 0.01;

// HISR's per-tile cuts (docs/algorithm.md section 4.4) come in
// HISR_CUT_LEVELS chained levels: level c has tiles of 2^(K + c) pixels a
// side; the coarsest is cut from the start depth, each finer one from its
// parent tile's "traverse" entries. Layout of the buffer (hisr_cut.comp
// writes it, gather.frag reads it): this header, then per level a count per
// tile, then per level `capacity` entries per tile (hisr.glsl: packed indices
// for evaluate entries, cut_entry for traverse entries):
// a tile's "evaluate" entries from the front of its range, its "traverse"
// entries from the back. A count holds the evaluate entries in bits 0-15 and
// the traverse entries in bits 16-31, or is HISR_CUT_OVERFLOW. Offsets count
// uints after the header.
const int HISR_CUT_LEVELS = 3;
struct HisrCutHeader {
    uvec4 tiles[HISR_CUT_LEVELS];  // per level: x, y: tiles per row and column; z: tile
                                   // level K + c; w: offset of its counts
    uvec4 entries;                 // y, z, w: offset of levels 0, 1, 2's entries; x: of the
                                   // finest tiles' boxes (8 floats each, hisr_cut.comp)
    uvec4 capacity;                // x, y, z: entries per tile of levels 0, 1, 2
};

// A tile whose cut did not fit: its fragments traverse from the roots.
const uint HISR_CUT_OVERFLOW = 4294967295u;

// hierarchy.w bits.
const int HIERARCHY_POINT_VPLS = 1;    // one texel per VPL patch, flux and area scaled up
// (Bit 2 is free: nearest or interpolated upsampling is a specialisation
// constant of upsample.comp.)
const int HIERARCHY_STENCIL_OFF = 4;   // gather every texel, mask afterwards

// Geometry-mip flag bits (image geo_flags).
const uint GEO_HAS_GEOMETRY = 1u;  // at least one pixel of the texel sees geometry
const uint GEO_SMOOTH = 2u;        // fully covered, depth range and normal spread under the thresholds
const uint GEO_SPLIT = 4u;         // has geometry and is not a leaf: not smooth, or 2:1 balance

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
    uint instance;  // index into the frame's InstanceTransform array
    uint material;  // index into the materials
};

// Push constants of the viewer's present pass (present.frag): the frame's
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

// Push constants of the viewer's text overlay (overlay_text.vert/.frag): a
// grid of 8x8 glyphs; each cell of the text buffer is `char | colour << 8`.
struct OverlayPush {
    ivec4 rect;    // xy: the grid's top-left corner (pixels); z, w: columns, rows
    ivec4 target;  // x, y: window size (pixels); z: screen pixels per glyph pixel; w: unused
};

#endif
