//! The renderer: creates a run's passes and method, records every frame,
//! submits it with up to two frames in flight, and destroys it all. What the
//! passes share (settings, targets, scene, uniforms) lives below it in
//! `frame`; reading results back lives in `readback` (the renderer's accessors
//! in `results`).
//!
//! Frames are recorded anew every frame: recording is cheap (tens of
//! commands), and it keeps the frame free to change shape (a method switch,
//! a swapchain image) without a separate "re-record when" rule. What changes
//! between frames (camera, light, instance transforms) is data in the frame
//! set of the frame's slot, written just before it is submitted.

use crate::frame::check::{check_light_views, check_ranges, check_settings, AddedMemory};
use crate::frame::uniforms::{frame_uniforms, instance_transforms};
use crate::frame::{FrameContext, FrameSet, Samplers, SceneGpu, Setup, Targets};
use crate::gpu_types::{FrameUniforms, RunUniforms};
use crate::methods::{Descriptor, IndirectMethod};
use crate::passes::light_sum::{LightSumPass, SumStep};
use crate::passes::rsm_cube::CubeRsmPass;
use crate::passes::rsm_tree::{self, RsmTreePass};
use crate::passes::{composite, direct_light, gbuffer, rsm, tonemap, FullscreenPass, ScenePass};
use crate::scene::{FrameState, LightKind, Scene};
use crate::settings::RenderSettings;
use crate::view::LightView;
use crate::visibility;
use crate::vk::profiler::{PassSample, Profiler};
use crate::voxel_grid::{self, VoxelGrid, VoxelizePass};

mod interactive;
mod results;
mod slot;
mod stats;
mod views;
use crate::vk::{Buffer, Gpu};
use anyhow::{bail, Context as _, Result};
use ash::vk;
pub use interactive::FrameExtension;
use slot::Slot;
pub use stats::{median, FrameStats};
use std::time::Instant;
use views::{all_views, mesh_bounds, relative, ViewFitting};

pub use crate::frame::FRAMES_IN_FLIGHT;

/// Passes a frame can hold besides the method's repeated ones; the profiler's
/// query pools are this large.
const MAX_PASSES: u32 = 32;

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

pub struct Renderer<'g> {
    gpu: &'g Gpu,
    pub settings: RenderSettings,
    /// The scene's bounds as loaded: they place the RSM near plane and fit
    /// directional lights' RSMs.
    bounds: (glam::Vec3, glam::Vec3),
    /// Each instance's mesh bounds in object space, for fitting directional
    /// lights' RSMs to the view (`view::fit_directional`).
    object_bounds: Vec<(glam::Vec3, glam::Vec3)>,
    /// What the GPU renders relative to (`scene::render_origin`): `state`,
    /// `views` and every position on the GPU are relative to it, and
    /// readbacks add it back.
    origin: glam::DVec3,
    /// The current frame state, relative to `origin`.
    state: FrameState,
    /// Every RSM a frame renders: one per spot or directional light, six per
    /// point light (`view::light_views`), from the current frame state.
    views: Vec<LightView>,
    /// Renders only this view (tests look at one cube face's RSM).
    only_view: Option<usize>,
    light_sum: Option<LightSumPass>,
    /// Pass `voxel-grid`, made when the run asks for `--visibility
    /// voxels`, and whether the current method reads it (`grid_in_use`).
    visibility_pass: Option<VoxelizePass>,
    grid_in_use: bool,
    /// Point lights' layered cube RSM (made only when the scene has one).
    rsm_cube: Option<CubeRsmPass>,
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
    /// The run uniforms' buffer, and the values it holds.
    run_uniforms: (Buffer, RunUniforms),
    /// The voxel visibility grid every frame set binds (16 bytes without
    /// `--visibility voxels`).
    voxel_grid: VoxelGrid,
    pub scene: SceneGpu,
    pub targets: Targets,
    _samplers: Samplers,
}

impl<'g> Renderer<'g> {
    /// Makes everything a run of `settings` on `scene` needs; the first frame
    /// shows `scene.rest_state()`. Whatever was made before an error is freed.
    pub fn new(gpu: &'g Gpu, scene: &Scene, settings: &RenderSettings) -> Result<Self> {
        let bounds = scene.bounds().unwrap_or((glam::Vec3::ZERO, glam::Vec3::X));
        let rest = scene.rest_state();
        let origin = crate::scene::render_origin(&rest.camera);
        let state = rest.relative_to(origin);
        let object_bounds: Vec<(glam::Vec3, glam::Vec3)> = scene
            .instances
            .iter()
            .map(|i| mesh_bounds(&scene.meshes[i.mesh]))
            .collect();
        let fitting = ViewFitting {
            bounds,
            origin,
            objects: &object_bounds,
            size: (settings.width, settings.height),
        };
        let views = all_views(&state, &fitting, settings.rsm_resolution);
        let descriptor = check_run(
            gpu,
            settings,
            &scene.lights,
            views.len(),
            scene.instances.len(),
        )?;
        let samplers = Samplers::new(gpu)?;
        let scene_gpu =
            SceneGpu::new(gpu, scene, samplers.texture).context("uploading the scene")?;
        let targets = Targets::new(gpu, settings)?;
        let run_values = run_uniforms(descriptor, settings);
        let run_uniforms = Buffer::with_data(
            gpu,
            "run uniforms",
            bytemuck::bytes_of(&run_values),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        // The slots' profilers are sized once the method says how many
        // submissions (repeated passes) its frames take, so the method comes
        // first, made with a provisional frame set of the same layout.
        let voxel_grid = VoxelGrid::new(gpu, settings, visibility::uses_voxels(settings))?;
        let first = FrameSet::new(
            gpu,
            &run_uniforms,
            &voxel_grid.occupancy,
            scene.instances.len(),
        )?;
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
        let light_sum = if views.len() > 1 {
            Some(LightSumPass::new(&setup)?)
        } else {
            None
        };
        let rsm_cube = if views.iter().any(|v| v.face.is_some()) {
            Some(CubeRsmPass::new(&setup)?)
        } else {
            None
        };
        // Made with `--visibility voxels` whatever the method, so that the
        // viewer can switch to one that reads it; recorded only for those.
        let grid_in_use = reads_grid(descriptor, settings);
        let visibility_pass = match visibility::uses_voxels(settings) {
            true => Some(VoxelizePass::new(&setup, &voxel_grid, scene)?),
            false => None,
        };
        drop(first);
        let passes = (MAX_PASSES + method.submissions() as u32) * views.len() as u32;
        let slots = (0..FRAMES_IN_FLIGHT)
            .map(|_| {
                Slot::new(
                    gpu,
                    (&run_uniforms, &voxel_grid.occupancy),
                    scene.instances.len(),
                    views.len(),
                    passes,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            gpu,
            settings: settings.clone(),
            bounds,
            object_bounds,
            origin,
            state,
            views,
            only_view: None,
            light_sum,
            visibility_pass,
            grid_in_use,
            rsm_cube,
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
            run_uniforms: (run_uniforms, run_values),
            voxel_grid,
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
        let kinds = |s: &FrameState| s.lights.iter().map(|l| l.kind).collect::<Vec<_>>();
        if kinds(state) != kinds(&self.state) {
            bail!(
                "a frame state's lights ({:?}) differ in number or kind from the scene's ({:?})",
                kinds(state),
                kinds(&self.state)
            );
        }
        self.origin = crate::scene::render_origin(&state.camera);
        self.state = state.relative_to(self.origin);
        let fitting = ViewFitting {
            bounds: self.bounds,
            origin: self.origin,
            objects: &self.object_bounds,
            size: (self.settings.width, self.settings.height),
        };
        self.views = all_views(&self.state, &fitting, self.settings.rsm_resolution);
        Ok(())
    }

    /// The frame uniforms of the current frame state, seen from the first
    /// light view.
    pub fn frame_uniforms(&self) -> FrameUniforms {
        self.view_uniforms(0)
    }

    /// The run uniforms every frame reads (fixed until a method switch).
    pub fn run_uniforms(&self) -> RunUniforms {
        self.run_uniforms.1
    }

    /// The frame uniforms of light view `v` (an index into `light_views`).
    pub fn view_uniforms(&self, v: usize) -> FrameUniforms {
        let bounds = relative(self.bounds, self.origin);
        let mut u = frame_uniforms(&self.state, &self.settings, &self.views[v], bounds);
        u.grid_cube = self.grid_cube();
        u
    }

    /// The voxel visibility grid's cube around the posed scene of the
    /// current frame state (relative to the render origin).
    pub fn grid_cube(&self) -> [f32; 4] {
        let boxes = self
            .object_bounds
            .iter()
            .zip(&self.state.instance_transforms)
            .map(|(b, m)| crate::view::transformed_box(m, *b));
        voxel_grid::grid_cube(
            boxes,
            voxel_grid::GRID.get(&self.settings),
            voxel_grid::SUBCELLS.get(&self.settings),
        )
    }

    /// The voxel visibility grid's buffer (its bits, `shaders/voxel_grid/march.glsl`).
    pub fn voxel_grid(&self) -> Option<&Buffer> {
        self.grid_in_use.then_some(&self.voxel_grid.occupancy)
    }

    /// The RSMs each frame renders, in order.
    pub fn light_views(&self) -> &[LightView] {
        &self.views
    }

    /// Renders only light view `v` from now on (`None`: all), as if its
    /// light were alone and that view its only RSM: the targets then hold that
    /// view's RSM and light tree.
    pub fn set_only_view(&mut self, v: Option<usize>) -> Result<()> {
        if let Some(v) = v {
            if v >= self.views.len() {
                bail!("light view {v} does not exist ({} views)", self.views.len());
            }
        }
        self.only_view = v;
        Ok(())
    }

    /// The views a frame renders: all, or the one `set_only_view` chose.
    fn active_views(&self) -> Vec<usize> {
        match self.only_view {
            Some(v) => vec![v],
            None => (0..self.views.len()).collect(),
        }
    }

    /// Command buffers (submissions) of one frame: a method that needs S
    /// submissions per view starts a new one for each of its chunks after
    /// the first.
    fn submissions(&self) -> usize {
        1 + self.active_views().len() * (self.method.submissions() - 1)
    }

    /// The method's passes and resources.
    pub fn method(&self) -> &dyn IndirectMethod {
        self.method.as_ref()
    }

    /// Records `slot`'s frame: the G-buffer, then for each light view its
    /// RSM, direct light, light tree and method passes (summed by
    /// `light-sum` when there are several; the method's camera-only passes
    /// only in the first view), then the composite, tonemap and what
    /// `extension` adds (the viewer's presentation). A `counting` frame holds
    /// the statistics and occlusion queries (`Profiler`).
    fn record(
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
                p.set_label(labels[i].clone());
            }
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
    fn complete(&mut self, slot: usize, stats: &mut FrameStats) -> Result<()> {
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

/// Checks `settings` for a run with `lights` (`views` RSMs, `instances`
/// transforms) on `gpu` before anything is allocated: the shared sizes, the
/// method's parameters and checks, then the memory it all takes. Returns
/// the method's descriptor.
fn check_run(
    gpu: &Gpu,
    settings: &RenderSettings,
    lights: &[crate::scene::Light],
    views: usize,
    instances: usize,
) -> Result<&'static dyn Descriptor> {
    check_ranges(settings)?;
    let d = crate::methods::check(settings)?;
    let method = crate::methods::memory(d, settings);
    check_settings(gpu, settings, method)?;
    crate::voxel_grid::check_device(gpu, settings)?;
    let cube_rsm = match lights.iter().any(|l| l.kind == LightKind::Point) {
        true => crate::passes::rsm_cube::cube_bytes(settings.rsm_resolution),
        false => 0,
    };
    check_light_views(
        gpu,
        settings,
        lights,
        (views, instances),
        AddedMemory { method, cube_rsm },
    )?;
    Ok(d)
}

/// Whether a run of `d` with `s` reads the voxel visibility grid.
fn reads_grid(d: &dyn Descriptor, s: &RenderSettings) -> bool {
    d.reads_visibility() && visibility::uses_voxels(s)
}

/// The run uniforms of `s`: the shared fields, the RSM tree's, then the
/// method's (`d`).
fn run_uniforms(d: &dyn Descriptor, s: &RenderSettings) -> RunUniforms {
    let mut u = crate::frame::uniforms::run_uniforms(s);
    rsm_tree::write_uniforms(s, &mut u);
    crate::methods::write_uniforms(d, s, &mut u);
    u
}

impl Drop for Renderer<'_> {
    fn drop(&mut self) {
        // Every object below frees itself; none may be in use by then.
        unsafe {
            let _ = self.gpu.device.device_wait_idle();
        }
    }
}
