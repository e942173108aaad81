//! Method `rsm-gather` (ALGORITHM.md section 5, Dachsbacher & Stamminger
//! 2005): every full-resolution pixel gathers the N regular VPLs. Pass
//! `rsm-gather`, `shaders/rsm_gather.frag` (barriers: `FullscreenPass::record`).
//! Reads the G-buffer and the RSM quadtree; writes `indirect`.

use crate::passes::{FrameContext, FullscreenPass, INDIRECT_GRAPHICS};
use crate::renderer::FrameInputs;
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::Gpu;
use anyhow::Result;

/// The bindings `rsm_gather.frag` and the splat shaders share: frame uniforms,
/// G-buffer position and normal, RSM quadtree position, normal and flux.
pub fn full_resolution_bindings<'a>(inputs: &'a FrameInputs) -> Vec<Binding<'a>> {
    let (t, s) = (inputs.targets, inputs.samplers);
    vec![
        Binding::Uniform(inputs.uniforms),
        Binding::Sampled(t.gbuffer_position.view, s.nearest),
        Binding::Sampled(t.gbuffer_normal.view, s.nearest),
        Binding::Sampled(t.rsm_position.view, s.nearest),
        Binding::Sampled(t.rsm_normal.view, s.nearest),
        Binding::Sampled(t.rsm_flux.view, s.nearest),
    ]
}

pub struct RsmGatherPass(FullscreenPass);

impl RsmGatherPass {
    pub fn new(gpu: &Gpu, inputs: &FrameInputs) -> Result<Self> {
        Ok(Self(FullscreenPass::with_push_constants(
            gpu,
            "rsm-gather",
            "rsm_gather.frag",
            &full_resolution_bindings(inputs),
            &[inputs.targets.indirect.format],
            8,
        )?))
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        // All VPLs: first 0, last past the end.
        let push: Vec<u8> = [0i32, i32::MAX]
            .iter()
            .flat_map(|v| v.to_ne_bytes())
            .collect();
        profiler.pass(ctx.gpu, ctx.cmd, "rsm-gather", INDIRECT_GRAPHICS, || {
            self.0
                .record_with(ctx.gpu, ctx.cmd, &[&ctx.targets.indirect], &push)
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.0.destroy(gpu);
    }
}
