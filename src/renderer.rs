//! The renderer: creates a run's passes and method, records every frame,
//! submits it with up to two frames in flight, and destroys it all. What the
//! passes share (settings, targets, scene, uniforms) lives below it in
//! `frame`; reading results back lives in `readback`.
//!
//! Frames are recorded anew every frame: recording is cheap (tens of
//! commands), and it keeps the frame free to change shape (a method switch,
//! a swapchain image) without a separate "re-record when" rule. What changes
//! between frames (camera, light, instance transforms) is data in the frame
//! set of the frame's slot, written just before it is submitted.

use crate::frame::check::check_settings;
use crate::frame::uniforms::{frame_uniforms, instance_transforms, run_uniforms};
use crate::frame::{FrameContext, FrameSet, Samplers, SceneGpu, Setup, Targets};
use crate::gpu_types::{FrameUniforms, LightPatch};
use crate::methods::IndirectMethod;
use crate::multires::MultiresBuffer;
use crate::passes::rsm_tree::RsmTreePass;
use crate::passes::{composite, direct_light, gbuffer, rsm, tonemap, FullscreenPass, ScenePass};
use crate::readback::{self, MultiresReadback, Readback};
use crate::scene::{FrameState, Scene};
use crate::settings::RenderSettings;
use crate::vk::profiler::{PassSample, Profiler};
use crate::vk::{Buffer, Gpu};
use anyhow::{bail, Context as _, Result};
use ash::vk;
use std::time::Instant;

/// Frames recorded and submitted ahead of the one being waited for.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// Passes a frame can hold besides the method's repeated ones; the profiler's
/// query pools are this large.
const MAX_PASSES: u32 = 32;

/// GPU numbers of every frame rendered, and the CPU-measured wall time of each.
#[derive(Clone, Debug, Default)]
pub struct FrameStats {
    pub frames: Vec<Vec<PassSample>>,
    /// Per frame, from its first submission to the moment its fence was seen
    /// signalled: at least its GPU time, more when it waited behind the frame
    /// before it.
    pub wall_ms: Vec<f64>,
    /// From the first submission to the last frame's completion.
    pub elapsed_ms: f64,
    /// Multiresolution patches per level of the last frame.
    pub patches_per_level: Option<Vec<u32>>,
}

impl FrameStats {
    /// Median over frames of the summed time of all passes, or of the passes
    /// that exist only for indirect light; `None` without timestamps.
    pub fn gpu_ms_median(&self, indirect_only: bool) -> Option<f64> {
        let sums: Vec<f64> = self
            .frames
            .iter()
            .filter_map(|f| {
                f.iter()
                    .filter(|p| !indirect_only || p.kind.indirect)
                    .map(|p| p.gpu_ms)
                    .try_fold(0.0, |acc, ms| Some(acc + ms?))
            })
            .collect();
        crate::report::median(&sums)
    }
}

/// What a caller adds to each frame of `Renderer::render_frame`: commands
/// recorded after `tonemap` into the frame's last command buffer (passes
/// timed with the frame's profiler), and the semaphores its submission waits
/// on and signals (a swapchain image's acquisition and presentation).
pub trait FrameExtension {
    fn record(&mut self, ctx: &FrameContext, profiler: &mut Profiler) -> Result<()>;
    /// A semaphore to wait on before the given stages.
    fn wait(&self) -> Option<(vk::Semaphore, vk::PipelineStageFlags2)>;
    fn signal(&self) -> Option<vk::Semaphore>;
}

/// Where `render_frames` is, for progress reports.
#[derive(Clone, Copy, Debug)]
pub struct FrameProgress {
    /// Frames finished.
    pub frame: u32,
    pub frames: u32,
    /// Submissions of the frame in progress finished, of `submissions`.
    pub submission: u32,
    pub submissions: u32,
}

/// One frame in flight: its frame set, command buffers, queries and fence.
struct Slot<'g> {
    gpu: &'g Gpu,
    frame: FrameSet,
    profiler: Profiler,
    cmds: Vec<vk::CommandBuffer>,
    fence: vk::Fence,
    /// The frame this slot holds while it is in flight, and when it was submitted.
    in_flight: Option<(u32, Instant)>,
}

impl<'g> Slot<'g> {
    fn new(gpu: &'g Gpu, run: &Buffer, instances: usize, passes: u32) -> Result<Self> {
        let frame = FrameSet::new(gpu, run, instances)?;
        let profiler = Profiler::new(gpu, passes)?;
        let fence = unsafe {
            gpu.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }?;
        Ok(Self {
            gpu,
            frame,
            profiler,
            cmds: Vec::new(),
            fence,
            in_flight: None,
        })
    }

    /// `n` command buffers, allocated on first use and reused after.
    fn command_buffers(&mut self, n: usize) -> Result<&[vk::CommandBuffer]> {
        while self.cmds.len() < n {
            let cmd = self.gpu.allocate_command_buffer()?;
            self.cmds.push(cmd);
        }
        Ok(&self.cmds[..n])
    }
}

impl Drop for Slot<'_> {
    fn drop(&mut self) {
        let d = &self.gpu.device;
        unsafe {
            if self.in_flight.is_some() {
                let _ = d.wait_for_fences(&[self.fence], true, u64::MAX);
            }
            if !self.cmds.is_empty() {
                d.free_command_buffers(self.gpu.command_pool, &self.cmds);
            }
            d.destroy_fence(self.fence, None);
        }
    }
}

pub struct Renderer<'g> {
    gpu: &'g Gpu,
    pub settings: RenderSettings,
    /// The diagonal of the scene's bounds as loaded (places the RSM near plane).
    scene_extent: f32,
    state: FrameState,
    method: Box<dyn IndirectMethod>,
    rsm: ScenePass,
    gbuffer: ScenePass,
    direct: FullscreenPass,
    rsm_tree: RsmTreePass,
    composite: FullscreenPass,
    tonemap: FullscreenPass,
    slots: Vec<Slot<'g>>,
    next_slot: usize,
    frames_submitted: u32,
    _run_uniforms: Buffer,
    pub scene: SceneGpu,
    pub targets: Targets,
    _samplers: Samplers,
}

impl<'g> Renderer<'g> {
    /// Makes everything a run of `settings` on `scene` needs; the first frame
    /// shows `scene.rest_state()`. Whatever was made before an error is freed.
    pub fn new(gpu: &'g Gpu, scene: &Scene, settings: &RenderSettings) -> Result<Self> {
        check_settings(gpu, settings)?;
        let samplers = Samplers::new(gpu)?;
        let scene_gpu =
            SceneGpu::new(gpu, scene, samplers.texture).context("uploading the scene")?;
        let targets = Targets::new(gpu, settings)?;
        let run_uniforms = Buffer::with_data(
            gpu,
            "run uniforms",
            bytemuck::bytes_of(&run_uniforms(settings)),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        // The slots' profilers are sized once the method says how many
        // submissions (repeated passes) its frames take, so the method comes
        // first, made with a provisional frame set of the same layout.
        let first = FrameSet::new(gpu, &run_uniforms, scene.instances.len())?;
        let setup = Setup {
            gpu,
            frame: &first.set,
            targets: &targets,
            samplers: &samplers,
            scene: &scene_gpu,
            settings,
        };
        let method = crate::methods::create(&setup)?;
        let rsm = rsm::new(&setup)?;
        let gbuffer = gbuffer::new(&setup)?;
        let direct = direct_light::new(&setup)?;
        let rsm_tree = RsmTreePass::new(&setup)?;
        let composite = composite::new(&setup)?;
        let tonemap = tonemap::new(&setup)?;
        drop(first);
        let passes = MAX_PASSES + method.submissions() as u32;
        let slots = (0..FRAMES_IN_FLIGHT)
            .map(|_| Slot::new(gpu, &run_uniforms, scene.instances.len(), passes))
            .collect::<Result<Vec<_>>>()?;
        let scene_extent = scene.bounds().map_or(1.0, |(lo, hi)| (hi - lo).length());
        Ok(Self {
            gpu,
            settings: settings.clone(),
            scene_extent,
            state: scene.rest_state(),
            method,
            rsm,
            gbuffer,
            direct,
            rsm_tree,
            composite,
            tonemap,
            slots,
            next_slot: 0,
            frames_submitted: 0,
            _run_uniforms: run_uniforms,
            scene: scene_gpu,
            targets,
            _samplers: samplers,
        })
    }

    /// Sets the camera, light and instance transforms of the frames rendered
    /// from now on. Nothing else is rebuilt.
    pub fn update(&mut self, state: &FrameState) -> Result<()> {
        if state.instance_transforms.len() != self.scene.instance_count {
            bail!(
                "a frame state has {} instance transforms; the scene has {} instances",
                state.instance_transforms.len(),
                self.scene.instance_count
            );
        }
        self.state = state.clone();
        Ok(())
    }

    /// The frame uniforms of the current frame state.
    pub fn frame_uniforms(&self) -> FrameUniforms {
        frame_uniforms(&self.state, &self.settings, self.scene_extent)
    }

    /// The method's passes and resources.
    pub fn method(&self) -> &dyn IndirectMethod {
        self.method.as_ref()
    }

    /// Records `slot`'s frame: the shared passes around the method's, then
    /// what `extension` adds (the viewer's presentation).
    fn record(&mut self, slot: usize, extension: Option<&mut dyn FrameExtension>) -> Result<()> {
        let gpu = self.gpu;
        let submissions = self.method.submissions();
        let Self {
            slots,
            method,
            scene,
            targets,
            ..
        } = self;
        let slot = &mut slots[slot];
        let cmds = slot.command_buffers(submissions)?.to_vec();
        let begin = |cmd| unsafe {
            gpu.device
                .begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
        };
        let ctx = |cmd| FrameContext {
            gpu,
            cmd,
            frame_set: slot.frame.set.set,
            scene,
            targets,
        };
        let p = &mut slot.profiler;
        begin(cmds[0])?;
        p.begin_frame(gpu, cmds[0]);
        self.rsm.record(&ctx(cmds[0]), p);
        self.gbuffer.record(&ctx(cmds[0]), p);
        self.direct.record(&ctx(cmds[0]), p);
        if method.reads_rsm_tree() {
            self.rsm_tree.record(&ctx(cmds[0]), p);
        }
        for (k, &cmd) in cmds.iter().enumerate() {
            if k > 0 {
                unsafe { gpu.device.end_command_buffer(cmds[k - 1])? };
                begin(cmd)?;
            }
            method.record(&ctx(cmd), p, k);
        }
        let last = cmds[submissions - 1];
        self.composite.record(&ctx(last), p);
        self.tonemap.record(&ctx(last), p);
        if let Some(e) = extension {
            e.record(&ctx(last), p)?;
        }
        unsafe { gpu.device.end_command_buffer(last)? };
        Ok(())
    }

    /// Waits for `slot`'s frame, if one is in flight, and adds its numbers to `stats`.
    fn complete(&mut self, slot: usize, stats: &mut FrameStats) -> Result<()> {
        let gpu = self.gpu;
        let s = &mut self.slots[slot];
        let Some((frame, submitted)) = s.in_flight.take() else {
            return Ok(());
        };
        gpu.wait(s.fence)?;
        stats.wall_ms.push(submitted.elapsed().as_secs_f64() * 1e3);
        stats.frames.push(s.profiler.read(gpu)?);
        debug_assert_eq!(stats.frames.len() as u32, frame + 1);
        Ok(())
    }

    /// Renders `n` frames of the current frame state, up to `FRAMES_IN_FLIGHT`
    /// at once, and returns every frame's per-pass numbers. `progress` is
    /// called as frames (and the submissions of multi-submission frames) finish.
    pub fn render_frames(
        &mut self,
        n: u32,
        mut progress: impl FnMut(FrameProgress),
    ) -> Result<FrameStats> {
        let gpu = self.gpu;
        let mut stats = FrameStats::default();
        let submissions = self.method.submissions() as u32;
        let started = Instant::now();
        let report = |stats: &FrameStats, submission| FrameProgress {
            frame: stats.frames.len() as u32,
            frames: n,
            submission,
            submissions,
        };
        for _ in 0..n {
            let slot = self.next_slot;
            self.next_slot = (slot + 1) % self.slots.len();
            // The slot's previous frame must finish before its buffers change.
            let had_frame = self.slots[slot].in_flight.is_some();
            self.complete(slot, &mut stats)?;
            if had_frame {
                progress(report(&stats, 0));
            }
            let uniforms = self.frame_uniforms();
            let transforms = instance_transforms(&self.state);
            self.slots[slot].frame.write(&uniforms, &transforms);
            self.record(slot, None)?;
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
        // Every frame has finished: the counts are the last frame's.
        stats.patches_per_level = self.method.multires().map(|m| m.patch_counts());
        Ok(stats)
    }

    /// Waits for the frame the next `render_frame` will replace, and returns
    /// its per-pass numbers (`None` when its slot held no frame). After this
    /// the semaphores that frame waited on may be reused.
    pub fn wait_next_slot(&mut self) -> Result<Option<Vec<PassSample>>> {
        let mut stats = FrameStats::default();
        self.complete(self.next_slot, &mut stats)?;
        Ok(stats.frames.pop())
    }

    /// Renders one frame of the current frame state, followed by what
    /// `extension` records (the viewer's presentation: the same frame as
    /// `render_frames`, plus a copy into a window). Does not wait for it;
    /// returns the numbers of the frame its slot held before, if any.
    pub fn render_frame(
        &mut self,
        extension: &mut dyn FrameExtension,
    ) -> Result<Option<Vec<PassSample>>> {
        let gpu = self.gpu;
        let finished = self.wait_next_slot()?;
        let slot = self.next_slot;
        self.next_slot = (slot + 1) % self.slots.len();
        let uniforms = self.frame_uniforms();
        let transforms = instance_transforms(&self.state);
        self.slots[slot].frame.write(&uniforms, &transforms);
        self.record(slot, Some(&mut *extension))?;
        let s = &mut self.slots[slot];
        let submissions = self.method.submissions();
        let cmds = s.cmds[..submissions].to_vec();
        for &cmd in &cmds[..submissions - 1] {
            gpu.submit_and_wait(cmd)?;
        }
        unsafe { gpu.device.reset_fences(&[s.fence])? };
        gpu.submit_with_semaphores(
            cmds[submissions - 1],
            s.fence,
            extension.wait(),
            extension.signal(),
        )?;
        s.in_flight = Some((self.frames_submitted, Instant::now()));
        self.frames_submitted += 1;
        Ok(finished)
    }

    /// The slot (of `FRAMES_IN_FLIGHT`) the next `render_frame` uses.
    pub fn next_slot_index(&self) -> usize {
        self.next_slot
    }

    /// A frame set: the layout of set 0 for pipelines made outside the
    /// renderer (all frame sets share one definition).
    pub fn frame_set_layout(&self) -> &crate::vk::pipeline::DescriptorSet {
        &self.slots[0].frame.set
    }

    /// Waits until no frame is in flight (before reading results back or
    /// changing what frames use); returns the per-pass numbers of the frames
    /// that were.
    pub fn wait_idle(&mut self) -> Result<Vec<Vec<PassSample>>> {
        let mut stats = FrameStats::default();
        for slot in 0..self.slots.len() {
            self.complete(slot, &mut stats)?;
        }
        Ok(stats.frames)
    }

    /// Switches to `settings`, which may differ from the current ones only in
    /// the method and its parameters (VPLs, thresholds, tau, ...): what the
    /// targets and shared passes are made from (sizes, RSM resolution) must
    /// stay. Only the method's resources are made anew; the run uniforms are
    /// rewritten. On error the renderer keeps its current method.
    pub fn set_method_settings(&mut self, settings: &RenderSettings) -> Result<()> {
        let old = &self.settings;
        if (settings.width, settings.height, settings.rsm_resolution)
            != (old.width, old.height, old.rsm_resolution)
        {
            bail!("set_method_settings cannot change the output size or the RSM resolution");
        }
        check_settings(self.gpu, settings)?;
        // The frames in flight were of the old method; their numbers go.
        self.wait_idle()?;
        let gpu = self.gpu;
        let setup = Setup {
            gpu,
            frame: &self.slots[0].frame.set,
            targets: &self.targets,
            samplers: &self._samplers,
            scene: &self.scene,
            settings,
        };
        let method = crate::methods::create(&setup)?;
        let passes = MAX_PASSES + method.submissions() as u32;
        for slot in &mut self.slots {
            slot.profiler = Profiler::new(gpu, passes)?;
        }
        let bytes = bytemuck::bytes_of(&run_uniforms(settings)).to_vec();
        let run = self._run_uniforms.buffer;
        gpu.run_once(|cmd| unsafe {
            // No frame is in flight (waited above); the update's writes
            // become visible to every later frame's reads.
            gpu.device.cmd_update_buffer(cmd, run, 0, &bytes);
            crate::vk::barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::AccessFlags2::TRANSFER_WRITE,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                vk::AccessFlags2::MEMORY_READ,
            );
        })?;
        self.method = method;
        self.settings = settings.clone();
        Ok(())
    }

    /// Copies every output of the last frame back to the host.
    pub fn readback(&self) -> Result<Readback> {
        readback::read_frame(self.gpu, &self.targets)
    }

    /// The multiresolution buffer of the last frame, if the method has one.
    pub fn readback_multires(&self) -> Result<Option<MultiresReadback>> {
        match self.method.multires() {
            Some(m) => Ok(Some(readback::read_multires(self.gpu, m, &self.targets)?)),
            None => Ok(None),
        }
    }

    /// The multiresolution buffer, if the method has one.
    pub fn multires(&self) -> Option<&MultiresBuffer> {
        self.method.multires()
    }

    /// The light patches Basic ISR chose in the last frame (`None` for other methods).
    pub fn isr_chosen(&self) -> Result<Option<Vec<LightPatch>>> {
        match self.method.chosen_patches() {
            Some(b) => Ok(Some(readback::read_chosen_patches(self.gpu, b)?)),
            None => Ok(None),
        }
    }

    /// How many light patches Basic ISR chose in the last frame.
    /// HISR's packed light tree, root first (`shaders/light_tree_pack.comp`).
    pub fn hisr_packed_tree(&self) -> Result<Option<Vec<LightPatch>>> {
        match self.method.packed_light_tree() {
            Some(b) => Ok(Some(readback::read_chosen_patches(self.gpu, b)?)),
            None => Ok(None),
        }
    }

    pub fn isr_chosen_count(&self) -> Result<Option<u32>> {
        Ok(self.isr_chosen()?.map(|c| c.len() as u32))
    }
}

impl Drop for Renderer<'_> {
    fn drop(&mut self) {
        // Every object below frees itself; none may be in use by then.
        unsafe {
            let _ = self.gpu.device.device_wait_idle();
        }
    }
}
