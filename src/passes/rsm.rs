//! Pass `rsm`: the reflective shadow map (ALGORITHM.md section 2), rendered
//! from the spot light with `shaders/scene.vert` + `shaders/rsm.frag`.
//! Reads the scene; writes `rsm_position`, `rsm_normal`, `rsm_flux`, `rsm_depth`
//! (barriers: `ScenePass::record`).

use super::{FrameContext, ScenePass, GRAPHICS};
use crate::renderer::SceneGpu;
use crate::vk::profiler::Profiler;
use crate::vk::Gpu;
use anyhow::Result;
use ash::vk;

/// position (xyz, valid), normal (xyz, area), flux (rgb, solid angle).
pub const FORMATS: [vk::Format; 3] = [vk::Format::R32G32B32A32_SFLOAT; 3];

pub struct RsmPass(ScenePass);

impl RsmPass {
    pub fn new(gpu: &Gpu, scene: &SceneGpu) -> Result<Self> {
        Ok(Self(ScenePass::new(
            gpu, "rsm", "rsm.frag", scene, &FORMATS, true,
        )?))
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let t = ctx.targets;
        profiler.pass(ctx.gpu, ctx.cmd, "rsm", GRAPHICS, || {
            self.0.record(
                ctx.gpu,
                ctx.cmd,
                ctx.scene,
                &[&t.rsm_position, &t.rsm_normal, &t.rsm_flux],
                &t.rsm_depth,
            )
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.0.destroy(gpu);
    }
}
