//! Pass `composite`: final radiance = direct + albedo/pi * indirect irradiance
//! (ALGORITHM.md section 2), `shaders/composite.frag`. Reads `direct`,
//! `gbuffer_albedo`, `indirect`; writes `final_radiance` (barriers: `FullscreenPass::record`).

use super::{FrameContext, FullscreenPass, GRAPHICS};
use crate::renderer::{Samplers, Targets};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::Result;
use ash::vk;

pub const FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

pub struct CompositePass(FullscreenPass);

impl CompositePass {
    pub fn new(gpu: &Gpu, uniforms: &Buffer, t: &Targets, s: &Samplers) -> Result<Self> {
        let bindings = [
            Binding::Uniform(uniforms),
            Binding::Sampled(t.direct.view, s.nearest),
            Binding::Sampled(t.gbuffer_albedo.view, s.nearest),
            Binding::Sampled(t.indirect.view, s.nearest),
        ];
        Ok(Self(FullscreenPass::new(
            gpu,
            "composite",
            "composite.frag",
            &bindings,
            &[FORMAT],
        )?))
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        profiler.pass(ctx.gpu, ctx.cmd, "composite", GRAPHICS, || {
            self.0
                .record(ctx.gpu, ctx.cmd, &[&ctx.targets.final_radiance])
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.0.destroy(gpu);
    }
}
