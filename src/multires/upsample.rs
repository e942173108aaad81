//! Pass `upsample`: the illumination buffer to a full-resolution indirect image
//! (docs/algorithm.md section 3, step 7): a pull from level 1 up to L and a push
//! from L - 1 down to 1 (`shaders/multires/upsample.comp`), then the push into level 0
//! as a full-screen draw into `indirect` (`shaders/multires/upsample_level0.frag`),
//! nearest or interpolated by a specialisation constant. The dispatch that
//! finalises a level l >= 1 (the pull of L, every push) writes the taps the
//! push into l - 1 reads (`upsample_taps`, `shaders/multires/upsample.glsl`).
//! Reads the illumination buffer and geometry mips; writes `indirect`.

use super::{MultiresBuffer, Upsample};
use crate::frame::{FrameContext, Setup};
use crate::passes::{begin_rendering, Attachments, ComputePass, INDIRECT_COMPUTE};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, GraphicsDesc, PassPipeline, Spec};
use crate::vk::profiler::Profiler;
use anyhow::Result;

/// One pipeline per kind of dispatch (`multires/upsample.comp`'s specialisation
/// constants): CPU drivers execute every branch of a shader under a lane mask,
/// so one shader for all kinds would run all their code per invocation.
pub struct UpsamplePass {
    pull: ComputePass,
    /// The pull into level L, which also writes its taps.
    pull_coarsest: ComputePass,
    /// The push into a level 1..L-1 (with its taps).
    push: ComputePass,
    /// The push into level 0, writing `indirect`.
    level_zero: PassPipeline,
}

impl UpsamplePass {
    pub fn new(setup: &Setup, m: &MultiresBuffer) -> Result<Self> {
        let (t, s) = (setup.targets, setup.samplers);
        let bindings = vec![
            Binding::storage_image("illumination", m.illumination.view),
            Binding::sampled("geo_mean", m.geo_mean.view, s.nearest),
            Binding::sampled("geo_normal", m.geo_normal.view, s.nearest),
            Binding::storage_image("taps", m.upsample_taps.view),
        ];
        // From these settings; a change of settings rebuilds the passes.
        let interpolate = Spec::bool(
            "INTERPOLATE",
            super::UPSAMPLE.get(setup.settings) == Upsample::Interpolated,
        );
        let pass = |pull: bool, taps: bool| {
            ComputePass::new(
                setup,
                "upsample",
                "multires/upsample.comp",
                std::slice::from_ref(&bindings),
                4,
                &[
                    Spec::bool("PULL", pull),
                    Spec::bool("WRITE_TAPS", taps),
                    interpolate,
                ],
            )
        };
        let level_zero = PassPipeline::graphics(
            setup.gpu,
            setup.frame,
            &[
                Binding::storage_image("illumination", m.illumination.view),
                Binding::storage_image("taps", m.upsample_taps.view),
            ],
            GraphicsDesc {
                name: "upsample",
                fragment_shader: "multires/upsample_level0.frag",
                color_formats: &[t.indirect.format],
                specialization: &[interpolate],
                ..Default::default()
            },
        )?;
        Ok(Self {
            pull: pass(true, false)?,
            pull_coarsest: pass(true, true)?,
            push: pass(false, true)?,
            level_zero,
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
                        &m.upsample_taps,
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
                let pass = match pull {
                    true if level == m.levels => &self.pull_coarsest,
                    true => &self.pull,
                    false => &self.push,
                };
                let push = (level as i32).to_ne_bytes();
                pass.dispatch(ctx, 0, &push, m.level_extent(level));
            };
            for level in 1..=m.levels {
                run(level, true);
            }
            for level in (1..m.levels).rev() {
                run(level, false);
            }
            // Level 0: the fragment shader reads what the dispatches wrote.
            barrier::images(
                gpu,
                cmd,
                &[
                    barrier::image(&m.illumination, Use::COMPUTE_STORAGE, Use::FRAGMENT_STORAGE),
                    barrier::image(
                        &m.upsample_taps,
                        Use::COMPUTE_STORAGE,
                        Use::FRAGMENT_STORAGE,
                    ),
                    barrier::image(
                        &t.indirect,
                        Use::DISCARD_AFTER_READERS,
                        Use::COLOR_ATTACHMENT,
                    ),
                ],
            );
            begin_rendering(
                gpu,
                cmd,
                // Every pixel is written: nothing to clear.
                &Attachments::loaded(&[t.indirect.view], t.indirect.extent),
            );
            self.level_zero.bind(gpu, cmd, ctx.frame_set);
            unsafe {
                gpu.device.cmd_draw(cmd, 3, 1, 0, 0);
                gpu.device.cmd_end_rendering(cmd);
            }
            barrier::images(
                gpu,
                cmd,
                &[
                    barrier::image(&m.illumination, Use::FRAGMENT_STORAGE, Use::READ_ONLY),
                    barrier::image(&m.upsample_taps, Use::FRAGMENT_STORAGE, Use::READ_ONLY),
                    barrier::image(&t.indirect, Use::COLOR_ATTACHMENT, Use::READ_ONLY),
                ],
            );
        });
    }
}
