//! Pass `upsample`: the illumination buffer to a full-resolution indirect image
//! (docs/algorithm.md section 3, step 7), `shaders/upsample.comp`: a pull from
//! level 1 up to L, then a push from L - 1 down to 0, which writes `indirect`
//! (nearest or interpolated, by a specialisation constant).
//! Reads the illumination buffer and geometry mips; writes `indirect`.

use super::{MultiresBuffer, Upsample};
use crate::frame::{FrameContext, Setup};
use crate::passes::{ComputePass, INDIRECT_COMPUTE};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use anyhow::Result;

/// One pipeline per kind of dispatch (`upsample.comp`'s specialisation
/// constants): CPU drivers execute every branch of a shader under a lane mask,
/// so one shader for all three would run all three's code per invocation.
pub struct UpsamplePass {
    pull: ComputePass,
    push: ComputePass,
    push_level_zero: ComputePass,
}

/// Specialisation constant ids of `upsample.comp`.
const PULL: u32 = 0;
const LEVEL_ZERO: u32 = 1;
const INTERPOLATE: u32 = 2;

impl UpsamplePass {
    pub fn new(setup: &Setup, m: &MultiresBuffer) -> Result<Self> {
        let (t, s) = (setup.targets, setup.samplers);
        let bindings = vec![
            Binding::storage_image("illumination", m.illumination.view),
            Binding::sampled("geo_mean", m.geo_mean.view, s.nearest),
            Binding::sampled("geo_normal", m.geo_normal.view, s.nearest),
            Binding::storage_image("indirect", t.indirect.view),
            Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
            Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
        ];
        // From these settings; a change of settings rebuilds the passes.
        let interpolate = (setup.settings.multires.upsample == Upsample::Interpolated) as i32;
        let pass = |pull: bool, level_zero: bool| {
            ComputePass::new(
                setup,
                "upsample",
                "upsample.comp",
                std::slice::from_ref(&bindings),
                4,
                &[
                    (PULL, pull as i32),
                    (LEVEL_ZERO, level_zero as i32),
                    (INTERPOLATE, interpolate),
                ],
            )
        };
        Ok(Self {
            pull: pass(true, false)?,
            push: pass(false, false)?,
            push_level_zero: pass(false, true)?,
        })
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
                let pass = match (pull, level) {
                    (true, _) => &self.pull,
                    (false, 0) => &self.push_level_zero,
                    (false, _) => &self.push,
                };
                let push = (level as i32).to_ne_bytes();
                pass.dispatch(ctx, 0, &push, m.level_extent(level));
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
}
