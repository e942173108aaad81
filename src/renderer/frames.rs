//! Recording and submitting frames: [`Renderer::render_frames`] writes each
//! slot's frame sets, records its command buffers (the shared passes, the
//! method's, and what an extension adds) and submits them, up to
//! `FRAMES_IN_FLIGHT` at once, then collects every frame's per-pass numbers.

use super::{FrameExtension, FrameProgress, FrameStats, Renderer};
use crate::frame::uniforms::instance_transforms;
use crate::frame::FrameContext;
use crate::passes::light_sum::SumStep;
use anyhow::Result;
use ash::vk;
use std::time::Instant;

impl Renderer<'_> {
    /// Records `slot`'s frame: the G-buffer, then for each light view its
    /// RSM, direct light, light tree, method and bounce passes (summed by
    /// `light-sum` when there are several; the method's camera-only passes
    /// only in the first view), then the composite, tonemap and what
    /// `extension` adds (the viewer's presentation). A `counting` frame holds
    /// the statistics and occlusion queries (`Profiler`).
    pub(super) fn record(
        &mut self,
        slot: usize,
        extension: Option<&mut dyn FrameExtension>,
        counting: bool,
    ) -> Result<()> {
        let gpu = self.gpu;
        let chunks = self.method.submissions();
        let active = self.active_views();
        let total = self.submissions();
        let labels: Vec<Option<String>> = active
            .iter()
            .map(|&v| (active.len() > 1).then(|| self.views[v].label()))
            .collect();
        // A point light's cube is drawn before the first of its faces this frame.
        let cube_first: Vec<Option<u32>> = active
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let view = &self.views[v];
                let first = i == 0 || self.views[active[i - 1]].light != view.light;
                view.face.filter(|_| first).map(|_| view.light as u32)
            })
            .collect();
        let cube = self.grid_cube();
        let Self {
            slots,
            method,
            scene,
            targets,
            ..
        } = self;
        let slot = &mut slots[slot];
        let cmds = slot.command_buffers(total)?.to_vec();
        let begin = |cmd| unsafe {
            gpu.device
                .begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
        };
        let sets: Vec<vk::DescriptorSet> = slot.frames.iter().map(|f| f.set.set).collect();
        let ctx = |cmd, v: usize| FrameContext {
            gpu,
            cmd,
            frame_set: sets[v],
            scene,
            targets,
        };
        let p = &mut slot.profiler;
        begin(cmds[0])?;
        p.begin_frame(gpu, cmds[0], counting);
        let mut c = 0;
        for (i, &v) in active.iter().enumerate() {
            match (self.views[v].face, &self.rsm_cube) {
                (Some(face), Some(cube)) => {
                    if let Some(light) = cube_first[i] {
                        p.set_label((active.len() > 1).then(|| light.to_string()));
                        cube.record_cube(&ctx(cmds[c], v), p);
                    }
                    p.set_label(labels[i].clone());
                    cube.record_face(&ctx(cmds[c], v), p, face as u32);
                }
                _ => {
                    p.set_label(labels[i].clone());
                    self.rsm.record(&ctx(cmds[c], v), p);
                }
            }
            if i == 0 {
                p.set_label(None);
                self.gbuffer.record(&ctx(cmds[c], v), p);
                // The posed scene's occupancy, shared by every light view.
                if let Some(grid) = self.visibility_pass.as_ref().filter(|_| self.grid_in_use) {
                    grid.record(&ctx(cmds[c], v), p, cube, &self.state.instance_transforms);
                }
                // ... and the surface in its cells, where the method reads it.
                if let Some(surface) = &self.surface_pass {
                    surface.record(&ctx(cmds[c], v), p);
                }
                p.set_label(labels[i].clone());
            }
            self.shadow.record(&ctx(cmds[c], v), p);
            self.direct.record(&ctx(cmds[c], v), p);
            if method.reads_rsm_tree() {
                self.rsm_tree.record(&ctx(cmds[c], v), p);
            }
            if i == 0 {
                // Camera-only passes, shared by every light view.
                p.set_label(None);
                method.record_eye_space(&ctx(cmds[c], v), p);
                p.set_label(labels[i].clone());
            }
            for k in 0..chunks {
                if k > 0 {
                    unsafe { gpu.device.end_command_buffer(cmds[c])? };
                    c += 1;
                    begin(cmds[c])?;
                }
                method.record(&ctx(cmds[c], v), p, k);
            }
            // Bounces 2..N of this view's light, added to the method's.
            if let Some(bounce) = &self.bounce {
                bounce.record(&ctx(cmds[c], v), p, v);
            }
            if let Some(sum) = &self.light_sum {
                if active.len() > 1 {
                    let step = match i {
                        0 => SumStep::First,
                        _ if i + 1 == active.len() => SumStep::Last,
                        _ => SumStep::Middle,
                    };
                    sum.record(&ctx(cmds[c], v), p, step);
                }
            }
        }
        p.set_label(None);
        let last = cmds[c];
        debug_assert_eq!(c + 1, total);
        self.composite.record(&ctx(last, active[0]), p);
        self.tonemap.record(&ctx(last, active[0]), p);
        if let Some(e) = extension {
            e.record(&ctx(last, active[0]), p)?;
        }
        unsafe { gpu.device.end_command_buffer(last)? };
        Ok(())
    }

    /// Waits for `slot`'s frame, if one is in flight, and adds its numbers to `stats`.
    pub(super) fn complete(&mut self, slot: usize, stats: &mut FrameStats) -> Result<()> {
        let gpu = self.gpu;
        let s = &mut self.slots[slot];
        let Some((_, submitted)) = s.in_flight.take() else {
            return Ok(());
        };
        gpu.wait(s.fence)?;
        stats.wall_ms.push(submitted.elapsed().as_secs_f64() * 1e3);
        stats.frames.push(s.profiler.read(gpu)?);
        stats.counted.push(s.profiler.counting());
        Ok(())
    }

    /// Renders `n` frames of the current frame state, up to `FRAMES_IN_FLIGHT`
    /// at once, and returns every frame's per-pass numbers: the last frame
    /// counts fragments and invocations, the others only time (`Profiler`).
    /// `progress` is called as frames (and the submissions of multi-submission
    /// frames) finish.
    pub fn render_frames(
        &mut self,
        n: u32,
        progress: impl FnMut(FrameProgress),
    ) -> Result<FrameStats> {
        self.render_frames_counting(n, true, progress)
    }

    /// [`Self::render_frames`], where the last frame counts only when
    /// `count_last` (a run of several calls counts once, in its last call).
    pub fn render_frames_counting(
        &mut self,
        n: u32,
        count_last: bool,
        mut progress: impl FnMut(FrameProgress),
    ) -> Result<FrameStats> {
        let gpu = self.gpu;
        let mut stats = FrameStats::default();
        let submissions = self.submissions() as u32;
        let started = Instant::now();
        let report = |stats: &FrameStats, submission| FrameProgress {
            frame: stats.frames.len() as u32,
            frames: n,
            submission,
            submissions,
        };
        for i in 0..n {
            let slot = self.next_slot;
            self.next_slot = (slot + 1) % self.slots.len();
            // The slot's previous frame must finish before its buffers change.
            let had_frame = self.slots[slot].in_flight.is_some();
            self.complete(slot, &mut stats)?;
            if had_frame {
                progress(report(&stats, 0));
            }
            let transforms = instance_transforms(&self.state);
            for v in 0..self.views.len() {
                let uniforms = self.view_uniforms(v);
                self.slots[slot].frames[v].write(&uniforms, &transforms);
            }
            // The last frame counts; the others only time (`Profiler`).
            self.record(slot, None, count_last && i + 1 == n)?;
            let s = &mut self.slots[slot];
            let submitted = Instant::now();
            let cmds = s.cmds[..submissions as usize].to_vec();
            for (k, &cmd) in cmds.iter().enumerate() {
                if k + 1 < cmds.len() {
                    // Parts of a long frame: each waited for, for progress.
                    gpu.submit_and_wait(cmd)?;
                    progress(report(&stats, k as u32 + 1));
                } else {
                    unsafe { gpu.device.reset_fences(&[s.fence])? };
                    gpu.submit(cmd, s.fence)?;
                }
            }
            s.in_flight = Some((self.frames_submitted, submitted));
            self.frames_submitted += 1;
        }
        // The frames still in flight, oldest first.
        let mut pending: Vec<(u32, usize)> = self
            .slots
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.in_flight.map(|(f, _)| (f, i)))
            .collect();
        pending.sort();
        for (_, slot) in pending {
            self.complete(slot, &mut stats)?;
            progress(report(&stats, 0));
        }
        stats.elapsed_ms = started.elapsed().as_secs_f64() * 1e3;
        // Every frame has finished: the counts are the last frame's, if it
        // counted (only a counting frame writes them).
        if stats.counted.last() == Some(&true) {
            stats.patches_per_level = self.method.multires().map(|m| m.patch_counts());
        }
        Ok(stats)
    }
}
