//! The uniforms: `FrameUniforms` from a frame's camera and light (written every
//! frame) and `RunUniforms` from the settings (written once), as
//! `shaders/shared.glsl` lays them out.

use crate::gpu_types::{self, FrameUniforms, InstanceTransform, RunUniforms};
use crate::scene::{FrameState, LightKind};
use crate::settings::{RenderSettings, VplSampling};
use crate::view::{self, LightView};

/// What the shaders need of `state` for an image of `s.width` x `s.height`,
/// seen from the light RSM `v` (one of `view::light_views` of `state`'s light
/// `v.light`).
pub fn frame_uniforms(state: &FrameState, s: &RenderSettings, v: &LightView) -> FrameUniforms {
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
        camera_position: cam.position().extend(1.0).to_array(),
        camera_forward: cam.forward().extend(0.0).to_array(),
        light_position: v.position.extend(range).to_array(),
        light_direction: v.direction.extend(0.0).to_array(),
        light_intensity: intensity.extend(intensity.max_element()).to_array(),
        light_cone: [scale, offset, v.half_extent, v.depth_range],
        light_kind: [kind, v.face.unwrap_or(0) as i32, v.light as i32, 0],
        cube_view_proj: v.cube.map(|m| m.to_cols_array_2d()),
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

/// What stays fixed for a run of `s`.
pub fn run_uniforms(s: &RenderSettings) -> RunUniforms {
    let side = ((s.effective_vpls() as f64).sqrt() as u32).max(1);
    let vpl_level = s.rsm_resolution.max(side).ilog2() - side.ilog2();
    let mut flags = 0;
    if s.vpl_sampling == VplSampling::Point {
        flags |= gpu_types::HIERARCHY_POINT_VPLS;
    }
    if !s.multires.stencil {
        flags |= gpu_types::HIERARCHY_STENCIL_OFF;
    }
    let chord = 2.0 * (0.5 * s.multires.normal_threshold_deg.to_radians()).sin();
    let lt = &s.light_tree;
    RunUniforms {
        shadow: [
            s.shadow_normal_offset,
            s.shadow_depth_bias,
            s.pcf_radius,
            s.shadow_slope_bias,
        ],
        exposure: [s.exposure, 0.0, 0.0, 0.0],
        size: [s.width, s.height, s.rsm_resolution, 0],
        refine: [s.multires.depth_threshold, chord, 0.0, 0.0],
        hierarchy: [s.levels() as i32, vpl_level as i32, side as i32, flags],
        light_tree: [
            crate::methods::hisr::subdivision_threshold(lt.tau, s.rsm_resolution),
            lt.depth_threshold,
            lt.normal_threshold_deg.to_radians().cos(),
            0.0,
        ],
        splat: [s.splat_threshold, 0.0, 0.0, 0.0],
        light_levels: [
            lt.start_level as i32,
            s.hisr_max_depth() as i32,
            s.isr_base_mip() as i32,
            s.rsm_resolution.ilog2() as i32,
        ],
    }
}
