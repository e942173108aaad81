//! Host mirrors of the structs in `shaders/shared.glsl`. `tests/layouts.rs`
//! checks every size and offset here against the compiled SPIR-V.

/// `FrameUniforms` (std140): per-frame constants of every pass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameUniforms {
    pub camera_view_proj: [[f32; 4]; 4],
    pub light_view_proj: [[f32; 4]; 4],
    pub camera_position: [f32; 4],
    pub camera_forward: [f32; 4],
    /// w: range in metres, 0 = none.
    pub light_position: [f32; 4],
    pub light_direction: [f32; 4],
    /// rgb: color * intensity in W/sr.
    pub light_intensity: [f32; 4],
    /// x, y: KHR angle scale and offset; z: tan(RSM half fov); w: RSM resolution.
    pub light_cone: [f32; 4],
    /// x: normal offset (RSM texels); y: constant relative depth bias; z: PCF tap
    /// spacing (texels); w: slope-scaled bias (texels along the slope).
    pub shadow: [f32; 4],
    /// x: exposure for the PNG.
    pub exposure: [f32; 4],
    /// x, y: output size; z: RSM resolution.
    pub size: [u32; 4],
    /// x: relative depth threshold; y: normal threshold as a chord length.
    pub refine: [f32; 4],
    /// x: coarsest level L; y: VPL level k of the RSM quadtree; z: VPLs per
    /// side; w: `HIERARCHY_*` flags.
    pub hierarchy: [i32; 4],
    /// x: HISR's T at the finest level; y: patch validity depth threshold
    /// (relative distance to the light); z: validity normal threshold (cosine);
    /// w: the light's peak intensity I (W/sr).
    pub light_tree: [f32; 4],
    /// x: HISR start depth; y: HISR max depth; z: ISR base mip; w: log2 R.
    pub light_levels: [i32; 4],
    /// x: restricted-splat threshold (W/m^2).
    pub splat: [f32; 4],
}

/// `LightPatch` (std430): one patch chosen by Basic ISR.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightPatch {
    /// xyz: mean position; w: area.
    pub position_area: [f32; 4],
    /// xyz: mean normal; w: quadtree level (RSM mip).
    pub normal: [f32; 4],
    /// rgb: flux; a: solid angle.
    pub flux: [f32; 4],
}

/// Header of the chosen-patch buffer before the `LightPatch` array.
pub const CHOSEN_PATCHES_HEADER: usize = 16;

/// RSM quadtree `normal.w` values, as in `shaders/shared.glsl`.
pub const PATCH_EMPTY: f32 = 0.0;
pub const PATCH_VALID: f32 = 1.0;
pub const PATCH_INVALID: f32 = -1.0;

/// `hierarchy.w` bits, as in `shaders/shared.glsl`.
pub const HIERARCHY_POINT_VPLS: i32 = 1;
pub const HIERARCHY_INTERPOLATE: i32 = 2;
pub const HIERARCHY_STENCIL_OFF: i32 = 4;

/// Geometry-mip flag bits, as in `shaders/shared.glsl`.
pub const GEO_HAS_GEOMETRY: u32 = 1;
pub const GEO_SMOOTH: u32 = 2;
pub const GEO_SPLIT: u32 = 4;

/// `MaterialGpu` (std430).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct MaterialGpu {
    pub base_color: [f32; 4],
    /// Texture index, -1 for none.
    pub texture: i32,
    pub pad: [i32; 3],
}

/// `DrawPush`: push constants of one scene draw.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct DrawPush {
    pub world_from_object: [[f32; 4]; 4],
    pub material: u32,
    pub pad: [u32; 3],
}

/// Views a `#[repr(C)]` plain-data value as bytes for upload.
pub fn bytes_of<T: Copy>(value: &T) -> &[u8] {
    // SAFETY: T is Copy plain data with no padding-dependent invariants; the
    // GPU reads the bytes as they are.
    unsafe { std::slice::from_raw_parts(value as *const T as *const u8, std::mem::size_of::<T>()) }
}

/// Views a slice of plain-data values as bytes for upload.
pub fn slice_bytes<T: Copy>(values: &[T]) -> &[u8] {
    // SAFETY: as in `bytes_of`.
    unsafe {
        std::slice::from_raw_parts(values.as_ptr() as *const u8, std::mem::size_of_val(values))
    }
}
