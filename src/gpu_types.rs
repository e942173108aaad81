//! Host mirrors of the structs in `shaders/shared.glsl`. `tests/layouts.rs`
//! checks every size and offset here against the compiled SPIR-V. All are
//! `Pod`: uploads and readbacks go through `bytemuck`, and a struct with
//! padding does not compile.

use bytemuck::{Pod, Zeroable};

/// `FrameUniforms` (std140): what changes every frame, the camera and the light.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FrameUniforms {
    pub camera_view_proj: [[f32; 4]; 4],
    pub light_view_proj: [[f32; 4]; 4],
    pub camera_position: [f32; 3],
    pub pad0: f32,
    pub camera_forward: [f32; 3],
    /// The G-buffer normal's w is view depth times this (`view::normal_depth_scale`).
    pub normal_depth_scale: f32,
    pub light_position: [f32; 3],
    /// Metres, 0 = none.
    pub light_range: f32,
    pub light_direction: [f32; 3],
    /// `LIGHT_*`.
    pub light_kind: i32,
    /// Color * intensity in W/sr.
    pub light_intensity: [f32; 3],
    /// The peak of `light_intensity`, I.
    pub light_peak: f32,
    /// KHR angle scale and offset (spot).
    pub cone_scale: f32,
    pub cone_offset: f32,
    /// tan(RSM half fov), or half the orthographic RSM's side (m).
    pub rsm_half_extent: f32,
    /// The orthographic RSM's depth range (m).
    pub rsm_depth_range: f32,
    pub cube_face: i32,
    pub light_index: i32,
    /// As `rsm_half_extent`, of the shadow map (`shadow_view_proj`).
    pub shadow_half_extent: f32,
    pub pad3: i32,
    /// Point lights: world -> clip of each cube face, for the layered draw.
    pub cube_view_proj: [[[f32; 4]; 4]; 6],
    /// The voxel grid's cube around this frame's posed scene: xyz its min
    /// corner, w a finest cell's side (m; `voxel_grid::grid_cube`).
    pub grid_cube: [f32; 4],
    /// The scene's bounds as loaded (relative to the render origin): fixed
    /// for a run, so what is fitted to them keeps its size as objects move.
    pub scene_min: [f32; 3],
    pub pad4: f32,
    pub scene_max: [f32; 3],
    pub pad5: f32,
    /// World -> shadow map clip (`view::LightView::shadow`).
    pub shadow_view_proj: [[f32; 4]; 4],
}

/// `FrameUniforms::light_kind` values, as in `shaders/shared.glsl`.
pub const LIGHT_SPOT: i32 = 0;
pub const LIGHT_POINT: i32 = 1;
pub const LIGHT_DIRECTIONAL: i32 = 2;

/// `RunUniforms` (std140): what is fixed for a run and shared by the passes
/// of every method. Each group is filled by the module that owns its
/// parameters (`shaders/shared.glsl` names them); a method's own parameters
/// reach its shaders as specialization constants instead.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RunUniforms {
    pub shadow_normal_offset: f32,
    pub shadow_depth_bias: f32,
    pub pcf_radius: f32,
    pub shadow_slope_bias: f32,
    pub output_size: [u32; 2],
    pub rsm_resolution: u32,
    pub rsm_top_level: i32,
    pub exposure: f32,
    /// The eye-space hierarchy (`multires::write_uniforms`).
    pub levels: i32,
    pub depth_threshold: f32,
    pub normal_chord: f32,
    /// `HIERARCHY_*` bits.
    pub hierarchy_flags: i32,
    /// Patch validity (`passes::rsm_tree::write_uniforms`).
    pub validity_depth: f32,
    pub validity_normal_cos: f32,
    /// How a merged light patch is evaluated (`passes::rsm_tree::PATCH_KERNEL`):
    /// `PATCH_KERNEL_*`.
    pub patch_kernel: i32,
    /// The voxel grid's finest side N and its level count
    /// (`voxel_grid::write_uniforms`).
    pub grid_side: i32,
    pub grid_levels: i32,
    /// S: the direct light's shadow map (`RenderSettings::shadow_size`).
    pub shadow_resolution: u32,
    pub pad1: i32,
    pub pad2: i32,
}

/// `RunUniforms::patch_kernel` values, as in `shaders/shared.glsl`.
pub const PATCH_KERNEL_CENTRE: i32 = 0;
pub const PATCH_KERNEL_SECOND_ORDER: i32 = 1;

/// `VoxelizePush`: one dispatch of pass `voxel-grid`, a range of one
/// instance's triangles.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct VoxelizePush {
    pub first_index: u32,
    pub vertex_offset: i32,
    pub instance: u32,
    pub first_triangle: u32,
    pub triangles: u32,
}

/// `GridLevelPush`: one dispatch of pass `voxel-grid`'s OR-levels, which
/// reads level `level` and writes `level + 1`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GridLevelPush {
    pub level: i32,
}

/// `InstanceTransform` (std430): where one mesh instance is this frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct InstanceTransform {
    pub world_from_object: [[f32; 4]; 4],
    /// Inverse transpose of the upper 3x3, for normals.
    pub normal_from_object: [[f32; 4]; 4],
}

impl InstanceTransform {
    pub fn new(world_from_object: glam::Mat4) -> Self {
        let normal = glam::Mat3::from_mat4(world_from_object)
            .inverse()
            .transpose();
        Self {
            world_from_object: world_from_object.to_cols_array_2d(),
            normal_from_object: glam::Mat4::from_mat3(normal).to_cols_array_2d(),
        }
    }
}

/// `LightPatch` (std430): one light patch, a node of the RSM quadtree, as the
/// lists a light-space source writes for the gather hold it
/// (`multires::LightSource`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightPatch {
    /// xyz: mean position; w: area.
    pub position_area: [f32; 4],
    /// xyz: mean normal; w: in a list, the quadtree level (RSM mip), negated
    /// where the patch spans a discontinuity (`patch_level` in
    /// `shaders/shared.glsl`); in a packed tree `PATCH_*`.
    pub normal: [f32; 4],
    /// rgb: flux; a: solid angle, or what the source keeps there (a packed
    /// tree: its squared reach).
    pub flux: [f32; 4],
}

/// Header of a light-patch buffer (its count, padded) before the
/// `LightPatch` array.
pub const LIGHT_PATCHES_HEADER: usize = 16;

/// RSM quadtree `normal.w` values, as in `shaders/shared.glsl`.
pub const PATCH_EMPTY: f32 = 0.0;
pub const PATCH_VALID: f32 = 1.0;
pub const PATCH_INVALID: f32 = -1.0;

/// `RunUniforms::hierarchy_flags` bits, as in `shaders/shared.glsl`.
pub const HIERARCHY_STENCIL_OFF: i32 = 4;

/// Geometry-mip flag bits, as in `shaders/shared.glsl`.
pub const GEO_HAS_GEOMETRY: u32 = 1;
pub const GEO_SMOOTH: u32 = 2;
pub const GEO_SPLIT: u32 = 4;

/// `MaterialGpu` (std430).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MaterialGpu {
    pub base_color: [f32; 4],
    /// The texture's array (`frame::texture_arrays`), -1 for none.
    pub texture_array: i32,
    /// Its layer in that array.
    pub texture_layer: i32,
    /// Where in the layer the texture is: sampled at `fract(uv) * scale +
    /// offset` (`TexturePlan::transform`).
    pub texture_scale: [f32; 2],
    pub texture_offset: [f32; 2],
    pub pad0: [f32; 2],
}

/// `DrawPush`: push constants of one scene draw.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DrawPush {
    /// Index into the frame's `InstanceTransform` array.
    pub instance: u32,
    pub material: u32,
}

/// `PresentPush`: push constants of the viewer's present pass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PresentPush {
    pub rect: [i32; 4],
    pub letterbox: [f32; 4],
    pub view: i32,
    pub srgb_target: i32,
    pub pad0: i32,
    pub pad1: i32,
}

/// `PresentPush.view` values, as in `shaders/shared.glsl`.
pub const PRESENT_VIEW_FINAL: i32 = 0;
pub const PRESENT_VIEW_INDIRECT: i32 = 1;
pub const PRESENT_VIEW_HOST: i32 = 2;

/// `OverlayPush`: push constants of the viewer's text overlay.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct OverlayPush {
    pub rect: [i32; 4],
    pub target: [i32; 4],
}
