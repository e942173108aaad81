//! Pass `upsample`: the illumination buffer to a full-resolution indirect image
//! (ALGORITHM.md section 3, step 7), `shaders/upsample.comp`: a pull from
//! level 1 up to L, then a push from L - 1 down to 0, which writes `indirect`
//! (nearest or interpolated, by a flag in the frame uniforms).
//! Reads the illumination buffer and geometry mips; writes `indirect`.

use super::MultiresBuffer;
use crate::passes::{ComputePass, FrameContext, INDIRECT_COMPUTE};
use crate::renderer::{Samplers, Targets};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::Result;

pub struct UpsamplePass(ComputePass);

impl UpsamplePass {
    pub fn new(
        gpu: &Gpu,
        uniforms: &Buffer,
        t: &Targets,
        s: &Samplers,
        m: &MultiresBuffer,
    ) -> Result<Self> {
        let bindings = vec![
            Binding::Uniform(uniforms),
            Binding::StorageImage(m.illumination.view),
            Binding::Sampled(m.geo_mean.view, s.nearest),
            Binding::Sampled(m.geo_normal.view, s.nearest),
            Binding::StorageImage(t.indirect.view),
        ];
        Ok(Self(ComputePass::new(
            gpu,
            "upsample",
            "upsample.comp",
            &[bindings],
            8,
            &[],
        )?))
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer) {
        let (gpu, cmd, t) = (ctx.gpu, ctx.cmd, ctx.targets);
        profiler.pass(gpu, cmd, "upsample", INDIRECT_COMPUTE, || {
            barrier::images(
                gpu,
                cmd,
                &[
                    barrier::image(&m.illumination, Use::READ_ONLY, Use::COMPUTE_STORAGE),
                    barrier::image(
                        &t.indirect,
                        Use::DISCARD_AFTER_READERS,
                        Use::COMPUTE_STORAGE,
                    ),
                ],
            );
            let mut first = true;
            let mut run = |level: u32, pull: bool| {
                if !first {
                    barrier::compute_to_compute(gpu, cmd);
                }
                first = false;
                let push: Vec<u8> = [level as i32, pull as i32]
                    .iter()
                    .flat_map(|v| v.to_ne_bytes())
                    .collect();
                self.0
                    .dispatch(gpu, cmd, 0, &push, m.geo_flags.mip_extent(level));
            };
            for level in 1..=m.levels {
                run(level, true);
            }
            for level in (0..m.levels).rev() {
                run(level, false);
            }
            barrier::transition(
                gpu,
                cmd,
                &[&m.illumination, &t.indirect],
                Use::COMPUTE_STORAGE,
                Use::READ_ONLY,
            );
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.0.destroy(gpu);
    }
}
