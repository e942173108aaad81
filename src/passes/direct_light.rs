//! Pass `direct`: direct radiance from the spot light with the RSM depth as a
//! PCF shadow map (ALGORITHM.md section 2), `shaders/direct_light.frag`.
//! Reads the G-buffer and `rsm_depth`; writes `direct` (barriers: `FullscreenPass::record`).

use super::{FrameContext, FullscreenPass, GRAPHICS};
use crate::renderer::{Samplers, Targets};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::Result;
use ash::vk;

pub const FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

pub struct DirectLightPass(FullscreenPass);

impl DirectLightPass {
    pub fn new(gpu: &Gpu, uniforms: &Buffer, t: &Targets, s: &Samplers) -> Result<Self> {
        let bindings = [
            Binding::Uniform(uniforms),
            Binding::Sampled(t.gbuffer_position.view, s.nearest),
            Binding::Sampled(t.gbuffer_normal.view, s.nearest),
            Binding::Sampled(t.gbuffer_albedo.view, s.nearest),
            Binding::Sampled(t.rsm_depth.view, s.shadow),
        ];
        Ok(Self(FullscreenPass::new(
            gpu,
            "direct",
            "direct_light.frag",
            &bindings,
            &[FORMAT],
        )?))
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        profiler.pass(ctx.gpu, ctx.cmd, "direct", GRAPHICS, || {
            self.0.record(ctx.gpu, ctx.cmd, &[&ctx.targets.direct])
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.0.destroy(gpu);
    }
}
