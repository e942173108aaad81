//! Pass `tonemap`: exposure and sRGB encoding of `final_radiance` into the
//! 8-bit `display` image written as the PNG, `shaders/tonemap.frag`
//! (barriers: `FullscreenPass::record`).

use super::{FrameContext, FullscreenPass, GRAPHICS};
use crate::renderer::{Samplers, Targets};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::Result;
use ash::vk;

/// The shader writes sRGB-encoded values itself, so the target is UNORM.
pub const FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

pub struct TonemapPass(FullscreenPass);

impl TonemapPass {
    pub fn new(gpu: &Gpu, uniforms: &Buffer, t: &Targets, s: &Samplers) -> Result<Self> {
        let bindings = [
            Binding::Uniform(uniforms),
            Binding::Sampled(t.final_radiance.view, s.nearest),
        ];
        Ok(Self(FullscreenPass::new(
            gpu,
            "tonemap",
            "tonemap.frag",
            &bindings,
            &[FORMAT],
        )?))
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        profiler.pass(ctx.gpu, ctx.cmd, "tonemap", GRAPHICS, || {
            self.0.record(ctx.gpu, ctx.cmd, &[&ctx.targets.display])
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.0.destroy(gpu);
    }
}
