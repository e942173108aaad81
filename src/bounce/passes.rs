//! The bounce passes (`bounce-cells`, `bounce-transfer` with `bounce-reach`,
//! `bounce-propagate`,
//! `bounce-gather`, `bounce-add`; docs/algorithm.md section 5.9) and their
//! buffers. Barriers: each pass waits for the previous one's storage writes
//! (`compute_to_compute`); the first waits for the previous frame's last
//! readers of the buffers it writes and for the RSM quadtree and G-buffer
//! (finished pass outputs, readable by the convention); `bounce-add` takes
//! `indirect` from its resting state to storage and back. With feedback the
//! views' kept powers are zeroed once, before the run's first frame reads
//! them, behind the same barriers.

use super::{
    feedback, propagations, CELLS, CELL_BYTES, HISTORY_BYTES, POWER_BYTES, REACH_BYTES, STEP, VPLS,
};
use crate::bounces::{Bounces, BOUNCES};
use crate::frame::{FrameContext, Setup};
use crate::passes::{ComputePass, INDIRECT_COMPUTE};
use crate::regular_vpls::RegularVpls;
use crate::visibility;
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::{Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// The bounce passes of a run with `--bounces` above 1.
pub struct BouncePass {
    cells: ComputePass,
    transfer: ComputePass,
    reach: ComputePass,
    propagate: ComputePass,
    gather: ComputePass,
    add: ComputePass,
    propagations: u32,
    /// The receivers' grid: pixels / STEP, rounded up.
    low: (u32, u32),
    extent: (u32, u32),
    /// `done` of `bounce-propagate`, cleared every frame.
    state: Buffer,
    /// With `--bounce-feedback on`: `bounce-feedback` instead of
    /// `bounce-propagate`, and each light view's kept power.
    feedback: Option<Feedback>,
    /// Every buffer the passes write, for the barrier before the first.
    _buffers: Vec<Buffer>,
}

/// The feedback pass (set `v` binds view `v`'s kept power) and the powers,
/// zeroed by the first frame recorded (`zeroed`).
struct Feedback {
    pass: ComputePass,
    history: Vec<Buffer>,
    zeroed: std::cell::Cell<bool>,
}

fn storage(gpu: &Gpu, name: &str, bytes: u64) -> Result<Buffer> {
    Buffer::new(
        gpu,
        name,
        bytes,
        vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuOnly,
    )
    .with_context(|| format!("the bounce passes' {name}"))
}

impl BouncePass {
    /// The passes of `setup`'s run over the grid's surface sums `surface`,
    /// for a frame of `views` light views; `None` with one bounce.
    pub fn new(setup: &Setup, surface: &Buffer, views: usize) -> Result<Option<Self>> {
        let Some(propagations) = propagations(setup.settings) else {
            return Ok(None);
        };
        let (gpu, s, t) = (setup.gpu, setup.settings, setup.targets);
        let cells_n = CELLS as u64;
        let cells = storage(gpu, "cells", cells_n * CELL_BYTES)?;
        let power_a = storage(gpu, "power", POWER_BYTES)?;
        let power_b = storage(gpu, "power (next)", POWER_BYTES)?;
        let power_sum = storage(gpu, "power summed", POWER_BYTES)?;
        let transfer = storage(gpu, "visibility", cells_n * cells_n * 4)?;
        let reach = storage(gpu, "reach", REACH_BYTES)?;
        let low = (s.width.div_ceil(STEP), s.height.div_ceil(STEP));
        let received = storage(gpu, "receivers", low.0 as u64 * low.1 as u64 * 16)?;
        let state = storage(gpu, "state", 16)?;
        // Every shader includes bounce/bounce.glsl, which declares it.
        let step = Spec::int("BOUNCE_STEP", STEP as i32);
        let vis = [&visibility::specialization(s)[..], &[step]].concat();
        let r = s.rsm_resolution as u64;
        let count = (VPLS as u64).min(r * r) as u32;
        let vpls = RegularVpls::with_count(s, count).specialization(s);
        let nearest = setup.samplers.nearest;
        let cells_pass = ComputePass::new(
            setup,
            "bounce-cells",
            "bounce/cells.comp",
            &[vec![
                Binding::storage("GridSurface", surface),
                Binding::storage("BounceCells", &cells),
                Binding::storage("BouncePower", &power_a),
                Binding::storage("BouncePowerSum", &power_sum),
                Binding::sampled("rsm_position", t.rsm_position.view, nearest),
                Binding::sampled("rsm_normal", t.rsm_normal.view, nearest),
                Binding::sampled("rsm_flux", t.rsm_flux.view, nearest),
            ]],
            0,
            &[&vis[..], &vpls[..]].concat(),
        )?;
        let transfer_pass = ComputePass::new(
            setup,
            "bounce-transfer",
            "bounce/transfer.comp",
            &[vec![
                Binding::storage("BounceCells", &cells),
                Binding::storage("BounceTransfer", &transfer),
            ]],
            0,
            &vis,
        )?;
        let reach_pass = ComputePass::new(
            setup,
            "bounce-reach",
            "bounce/reach.comp",
            &[vec![
                Binding::storage("BounceCells", &cells),
                Binding::storage("BounceTransfer", &transfer),
                Binding::storage("BounceReach", &reach),
            ]],
            0,
            &vis,
        )?;
        let ping_pong = |from, to| {
            vec![
                Binding::storage("BounceCells", &cells),
                Binding::storage("BounceTransfer", &transfer),
                Binding::storage("PowerIn", from),
                Binding::storage("PowerOut", to),
                Binding::storage("BouncePowerSum", &power_sum),
                Binding::storage("BounceState", &state),
                Binding::storage("BounceReach", &reach),
            ]
        };
        let propagate = ComputePass::new(
            setup,
            "bounce-propagate",
            "bounce/propagate.comp",
            &[ping_pong(&power_a, &power_b), ping_pong(&power_b, &power_a)],
            0,
            &[
                &vis[..],
                &[Spec::bool(
                    "BOUNCE_INFINITE",
                    BOUNCES.get(s) == Bounces::Infinite,
                )],
            ]
            .concat(),
        )?;
        let gbuffer = |b: &mut Vec<Binding>| {
            b.push(Binding::sampled(
                "gbuffer_position",
                t.gbuffer_position.view,
                nearest,
            ));
            b.push(Binding::sampled(
                "gbuffer_normal",
                t.gbuffer_normal.view,
                nearest,
            ));
        };
        let feedback = match feedback(s) {
            true => {
                let history = (0..views)
                    .map(|_| storage(gpu, "power kept for the next frame", HISTORY_BYTES))
                    .collect::<Result<Vec<_>>>()?;
                let sets: Vec<Vec<Binding>> = history
                    .iter()
                    .map(|h| {
                        vec![
                            Binding::storage("BounceCells", &cells),
                            Binding::storage("BounceTransfer", &transfer),
                            Binding::storage("BouncePowerSum", &power_sum),
                            Binding::storage("BounceHistory", h),
                            Binding::storage("BounceReach", &reach),
                        ]
                    })
                    .collect();
                let pass = ComputePass::new(
                    setup,
                    "bounce-feedback",
                    "bounce/feedback.comp",
                    &sets,
                    0,
                    &vis,
                )?;
                Some(Feedback {
                    pass,
                    history,
                    zeroed: std::cell::Cell::new(false),
                })
            }
            false => None,
        };
        let mut gather_bindings = vec![];
        gbuffer(&mut gather_bindings);
        gather_bindings.extend([
            Binding::storage("BounceCells", &cells),
            Binding::storage("BouncePowerSum", &power_sum),
            Binding::storage("BounceReceived", &received),
        ]);
        let gather = ComputePass::new(
            setup,
            "bounce-gather",
            "bounce/gather.comp",
            &[gather_bindings],
            0,
            &vis,
        )?;
        let mut add_bindings = vec![];
        gbuffer(&mut add_bindings);
        add_bindings.extend([
            Binding::storage("BounceReceived", &received),
            Binding::storage_image("indirect", t.indirect.view),
        ]);
        let add = ComputePass::new(
            setup,
            "bounce-add",
            "bounce/add.comp",
            &[add_bindings],
            0,
            &[step],
        )?;
        Ok(Some(Self {
            cells: cells_pass,
            transfer: transfer_pass,
            reach: reach_pass,
            propagate,
            gather,
            add,
            propagations,
            low,
            extent: (s.width, s.height),
            state,
            feedback,
            _buffers: vec![
                cells, power_a, power_b, power_sum, transfer, reach, received,
            ],
        }))
    }

    /// Records the passes of light view `view` (an index of the frame's
    /// views), after the method's: they add bounces 2..N of this view's
    /// light to `indirect`.
    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, view: usize) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let rw = vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
        let compute = vk::PipelineStageFlags2::COMPUTE_SHADER;
        profiler.pass(gpu, cmd, "bounce-cells", INDIRECT_COMPUTE, || {
            // The kept powers hold nothing before the run's first frame
            // (the buffers come uninitialised).
            if let Some(f) = self.feedback.as_ref().filter(|f| !f.zeroed.get()) {
                for h in &f.history {
                    let (after, before) = ((compute, rw), (compute, rw));
                    barrier::zero_buffer(gpu, cmd, h.buffer, vk::WHOLE_SIZE, after, before);
                }
                f.zeroed.set(true);
            }
            // The previous view's or frame's readers of every buffer before
            // they are written again.
            barrier::memory(gpu, cmd, compute, rw, compute, rw);
            self.cells.dispatch_groups(ctx, 0, &[], (CELLS, 1));
            barrier::compute_to_compute(gpu, cmd);
        });
        // Two bounces reach receivers from the cells' first: no transfer.
        if self.propagations > 0 {
            self.record_propagation(ctx, profiler, view);
        }
        profiler.pass(gpu, cmd, "bounce-gather", INDIRECT_COMPUTE, || {
            self.gather.dispatch_groups(
                ctx,
                0,
                &[],
                (self.low.0.div_ceil(8), self.low.1.div_ceil(8)),
            );
            barrier::compute_to_compute(gpu, cmd);
        });
        profiler.pass(gpu, cmd, "bounce-add", INDIRECT_COMPUTE, || {
            let indirect = &ctx.targets.indirect;
            barrier::transition(gpu, cmd, &[indirect], Use::READ_ONLY, Use::COMPUTE_STORAGE);
            let (width, height) = self.extent;
            self.add
                .dispatch(ctx, 0, &[], vk::Extent2D { width, height });
            barrier::transition(gpu, cmd, &[indirect], Use::COMPUTE_STORAGE, Use::READ_ONLY);
        });
    }

    /// `bounce-transfer`, then bounces 3..N among the cells, or with
    /// feedback one propagation from `view`'s kept power.
    fn record_propagation(&self, ctx: &FrameContext, profiler: &mut Profiler, view: usize) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let rw = vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
        let compute = vk::PipelineStageFlags2::COMPUTE_SHADER;
        profiler.pass(gpu, cmd, "bounce-transfer", INDIRECT_COMPUTE, || {
            self.transfer
                .dispatch_groups(ctx, 0, &[], (CELLS / 8, CELLS / 8));
            barrier::compute_to_compute(gpu, cmd);
            // The faces' reach, from the visibility just written.
            self.reach.dispatch_groups(ctx, 0, &[], (CELLS / 64, 1));
            barrier::compute_to_compute(gpu, cmd);
        });
        if let Some(f) = &self.feedback {
            profiler.pass(gpu, cmd, "bounce-feedback", INDIRECT_COMPUTE, || {
                f.pass.dispatch_groups(ctx, view, &[], (1, 1));
                barrier::compute_to_compute(gpu, cmd);
            });
            return;
        }
        profiler.pass(gpu, cmd, "bounce-propagate", INDIRECT_COMPUTE, || {
            // `done` starts clear, after the previous view's last reader.
            barrier::zero_buffer(
                gpu,
                cmd,
                self.state.buffer,
                vk::WHOLE_SIZE,
                (compute, rw),
                (compute, rw),
            );
            for k in 0..self.propagations {
                self.propagate
                    .dispatch_groups(ctx, (k % 2) as usize, &[], (1, 1));
                barrier::compute_to_compute(gpu, cmd);
            }
        });
    }
}
