//! Pass `gbuffer`: depth, world position, normal and albedo from the camera
//! (ALGORITHM.md section 3, step 1), with `shaders/scene.vert` +
//! `shaders/gbuffer.frag`. Reads the scene; writes `gbuffer_position`,
//! `gbuffer_normal`, `gbuffer_albedo`, `gbuffer_depth` (barriers: `ScenePass::record`).

use super::{FrameContext, ScenePass, GRAPHICS};
use crate::renderer::SceneGpu;
use crate::vk::profiler::Profiler;
use crate::vk::Gpu;
use anyhow::Result;
use ash::vk;

/// position (xyz, view depth), normal, albedo.
pub const FORMATS: [vk::Format; 3] = [
    vk::Format::R32G32B32A32_SFLOAT,
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::R16G16B16A16_SFLOAT,
];

pub struct GBufferPass(ScenePass);

impl GBufferPass {
    pub fn new(gpu: &Gpu, scene: &SceneGpu) -> Result<Self> {
        Ok(Self(ScenePass::new(
            gpu,
            "gbuffer",
            "gbuffer.frag",
            scene,
            &FORMATS,
            false,
        )?))
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let t = ctx.targets;
        profiler.pass(ctx.gpu, ctx.cmd, "gbuffer", GRAPHICS, || {
            self.0.record(
                ctx.gpu,
                ctx.cmd,
                ctx.scene,
                &[&t.gbuffer_position, &t.gbuffer_normal, &t.gbuffer_albedo],
                &t.gbuffer_depth,
            )
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.0.destroy(gpu);
    }
}
