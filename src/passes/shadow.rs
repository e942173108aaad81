//! Pass `shadow`: the direct light's shadow map (docs/algorithm.md section
//! 2.2), depth only, S x S (`RenderSettings::shadow_size`), rendered per
//! light view from its shadow frustum (`view::LightView::shadow`) with
//! `shaders/scene.vert` + `shaders/shadow.frag`. Its own image rather than
//! the RSM's depth, so that shadows do not depend on the RSM's size (the
//! VPL budget): a depth-only pass costs a fraction of the RSM's three
//! 128-bit colour targets and their quadtree at the same size.
//! Reads the scene; writes `depth` (barriers in `record`), which pass
//! `direct` reads.

use super::{begin_rendering, draw_scene_sets, Attachments, GRAPHICS};
use crate::frame::targets::DEPTH_FORMAT;
use crate::frame::{FrameContext, Setup};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{GraphicsDesc, Pipeline, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::{Image, ImageDesc};
use anyhow::Result;
use ash::vk;

pub struct ShadowPass {
    pipeline: Pipeline,
    /// Reversed-Z depth from the light view's shadow frustum.
    pub depth: Image,
}

impl ShadowPass {
    pub fn new(setup: &Setup) -> Result<Self> {
        let s = setup.settings.shadow_size();
        let depth = Image::new(
            setup.gpu,
            &ImageDesc {
                name: "shadow_depth",
                format: DEPTH_FORMAT,
                extent: vk::Extent2D {
                    width: s,
                    height: s,
                },
                layers: 1,
                mips: 1,
                usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            },
        )?;
        let pipeline = Pipeline::graphics(
            setup.gpu,
            &GraphicsDesc {
                name: "shadow",
                vertex_shader: "scene.vert",
                fragment_shader: "shadow.frag",
                sets: &[setup.frame],
                push_constant_bytes: std::mem::size_of::<crate::gpu_types::DrawPush>() as u32,
                scene_vertices: true,
                color_formats: &[],
                depth_format: DEPTH_FORMAT,
                depth_test: Some(vk::CompareOp::GREATER),
                dynamic_cull: true,
                specialization: &[Spec::int("VIEW_FROM_LIGHT", 2)],
                ..Default::default()
            },
        )?;
        Ok(Self { pipeline, depth })
    }

    /// Clears and fills the depth with the scene (single-sided faces turned
    /// from the light culled, as in the RSM), leaving it readable.
    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let depth = &self.depth;
        profiler.pass(gpu, cmd, "shadow", GRAPHICS, || {
            barrier::transition(
                gpu,
                cmd,
                &[depth],
                Use::DISCARD_AFTER_READERS,
                Use::DEPTH_ATTACHMENT,
            );
            begin_rendering(
                gpu,
                cmd,
                &Attachments::simple(&[], Some(depth.view), depth.extent),
            );
            draw_scene_sets(ctx, &self.pipeline, ctx.scene, 1, &[ctx.frame_set], true);
            unsafe { gpu.device.cmd_end_rendering(cmd) };
            barrier::transition(gpu, cmd, &[depth], Use::DEPTH_ATTACHMENT, Use::READ_ONLY);
        });
    }
}
