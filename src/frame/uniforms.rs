//! The uniforms: `FrameUniforms` from a frame's camera and light (written every
//! frame) and `RunUniforms` from the settings (written once), as
//! `shaders/shared.glsl` lays them out.

use crate::gpu_types::{self, FrameUniforms, InstanceTransform, RunUniforms};
use crate::scene::{FrameState, LightKind};
use crate::settings::RenderSettings;
use crate::view::{self, LightView};

/// What the shaders need of `state` for an image of `s.width` x `s.height`,
/// seen from the light RSM `v` (one of `view::light_views` of `state`'s light
/// `v.light`), for a scene within `bounds` (in `state`'s frame).
pub fn frame_uniforms(
    state: &FrameState,
    s: &RenderSettings,
    v: &LightView,
    bounds: (glam::Vec3, glam::Vec3),
) -> FrameUniforms {
    let cam = &state.camera;
    let l = &state.lights[v.light];
    let (scale, offset) = l.cone_scale_offset();
    let intensity = l.color * l.intensity;
    let kind = match v.kind {
        LightKind::Spot => gpu_types::LIGHT_SPOT,
        LightKind::Point => gpu_types::LIGHT_POINT,
        LightKind::Directional => gpu_types::LIGHT_DIRECTIONAL,
    };
    let range = match (v.kind, l.range) {
        (LightKind::Directional, _) | (_, None) => 0.0,
        (_, Some(r)) => r,
    };
    FrameUniforms {
        camera_view_proj: view::camera_view_proj(cam, s.width, s.height).to_cols_array_2d(),
        light_view_proj: v.view_proj.to_cols_array_2d(),
        camera_position: cam.position().to_array(),
        camera_forward: cam.forward().to_array(),
        normal_depth_scale: view::normal_depth_scale(cam.position(), bounds),
        light_position: v.position.to_array(),
        light_range: range,
        light_direction: v.direction.to_array(),
        light_kind: kind,
        light_intensity: intensity.to_array(),
        light_peak: intensity.max_element(),
        cone_scale: scale,
        cone_offset: offset,
        rsm_half_extent: v.half_extent,
        rsm_depth_range: v.depth_range,
        cube_face: v.face.unwrap_or(0) as i32,
        light_index: v.light as i32,
        cube_view_proj: v.cube.map(|m| m.to_cols_array_2d()),
        scene_min: bounds.0.to_array(),
        scene_max: bounds.1.to_array(),
        shadow_view_proj: v.shadow.view_proj.to_cols_array_2d(),
        shadow_half_extent: v.shadow.half_extent,
        ..Default::default()
    }
}

/// The world and normal transform of every instance of `state`.
pub fn instance_transforms(state: &FrameState) -> Vec<InstanceTransform> {
    state
        .instance_transforms
        .iter()
        .map(|m| InstanceTransform::new(*m))
        .collect()
}

/// What stays fixed for a run of `s`, as far as every run shares it: the
/// shadow constants and the sizes. The other fields belong to the modules
/// that own their parameters (the RSM tree's validity, the method's), which
/// write them after this.
pub fn run_uniforms(s: &RenderSettings) -> RunUniforms {
    RunUniforms {
        shadow_normal_offset: s.shadow_normal_offset,
        shadow_depth_bias: s.shadow_depth_bias,
        pcf_radius: s.pcf_radius,
        shadow_slope_bias: s.shadow_slope_bias,
        output_size: [s.width, s.height],
        rsm_resolution: s.rsm_resolution,
        rsm_top_level: s.rsm_top_level() as i32,
        shadow_resolution: s.shadow_size(),
        exposure: s.exposure,
        ..Default::default()
    }
}
