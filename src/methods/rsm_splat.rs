//! Methods `rsm-splat` and `rsm-splat-restricted` (ALGORITHM.md section 5):
//! each of the N regular VPLs draws a quad, full screen or bounded to where its
//! contribution can exceed `--splat-threshold` (D&S 2006), and its fragments
//! add that VPL's irradiance into the float target (blend ONE + ONE).
//! Pass `rsm-splat`: `shaders/vpl_splat.vert` + `shaders/vpl_splat.frag`, one
//! instanced draw (instance = VPL). Reads the G-buffer and RSM quadtree;
//! writes `indirect` (barriers below).

use super::rsm_gather::full_resolution_bindings;
use crate::passes::{begin_rendering, Attachments, FrameContext, INDIRECT_GRAPHICS};
use crate::renderer::FrameInputs;
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Blend, DescriptorSet, GraphicsDesc, Pipeline};
use crate::vk::profiler::Profiler;
use crate::vk::Gpu;
use anyhow::{bail, Result};
use ash::vk;

/// Fails with a clear message when `format` cannot be blended into.
pub fn require_blending(gpu: &Gpu, format: vk::Format, method: &str) -> Result<()> {
    let blendable = vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND;
    if gpu.pick_format(&[format], blendable).is_none() {
        bail!(
            "{} cannot blend into {format:?} render targets, which method {method} splats into; choose another method",
            gpu.info.name
        );
    }
    Ok(())
}

pub struct RsmSplatPass {
    pipeline: Pipeline,
    set: DescriptorSet,
    vpls: u32,
}

impl RsmSplatPass {
    pub fn new(gpu: &Gpu, inputs: &FrameInputs, vpls: u32, restricted: bool) -> Result<Self> {
        let format = inputs.targets.indirect.format;
        require_blending(gpu, format, "rsm-splat")?;
        let set = DescriptorSet::new(gpu, "rsm-splat", &full_resolution_bindings(inputs))?;
        let pipeline = Pipeline::graphics(
            gpu,
            &GraphicsDesc {
                name: "rsm-splat",
                vertex_shader: "vpl_splat.vert",
                fragment_shader: "vpl_splat.frag",
                set_layouts: &[set.layout],
                color_formats: &[format],
                blend: Blend::Additive,
                specialization: &[(0, restricted as i32)],
                ..Default::default()
            },
        )?;
        Ok(Self {
            pipeline,
            set,
            vpls,
        })
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd, indirect) = (ctx.gpu, ctx.cmd, &ctx.targets.indirect);
        profiler.pass(gpu, cmd, "rsm-splat", INDIRECT_GRAPHICS, || unsafe {
            barrier::transition(
                gpu,
                cmd,
                &[indirect],
                Use::DISCARD_AFTER_READERS,
                Use::COLOR_ATTACHMENT,
            );
            // Cleared to zero by the load op, then every splat adds.
            let colors = [indirect.view];
            begin_rendering(
                gpu,
                cmd,
                &Attachments::simple(&colors, None, indirect.extent),
            );
            self.pipeline
                .bind(gpu, cmd, vk::PipelineBindPoint::GRAPHICS, self.set.set);
            gpu.device.cmd_draw(cmd, 6, self.vpls, 0, 0);
            gpu.device.cmd_end_rendering(cmd);
            barrier::transition(gpu, cmd, &[indirect], Use::COLOR_ATTACHMENT, Use::READ_ONLY);
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.pipeline.destroy(gpu);
        self.set.destroy(gpu);
    }
}
