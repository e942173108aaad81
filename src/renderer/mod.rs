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

use crate::bounce::BouncePass;
use crate::frame::check::{
    check_light_views, check_ranges, check_settings, check_textures, AddedMemory,
};
use crate::frame::texture_arrays::TexturePlan;
use crate::frame::uniforms::{frame_uniforms, instance_transforms};
use crate::frame::{FrameContext, FrameSet, Samplers, SceneGpu, Setup, Targets};
use crate::gpu_types::{FrameUniforms, RunUniforms};
use crate::methods::{Descriptor, IndirectMethod};
use crate::passes::light_sum::LightSumPass;
use crate::passes::rsm_cube::CubeRsmPass;
use crate::passes::rsm_tree::{self, RsmTreePass};
use crate::passes::shadow::ShadowPass;
use crate::passes::{composite, direct_light, gbuffer, rsm, tonemap, FullscreenPass, ScenePass};
use crate::scene::{FrameState, LightKind, Scene};
use crate::settings::RenderSettings;
use crate::view::LightView;
use crate::visibility;
use crate::vk::profiler::{PassSample, Profiler};
use crate::voxel_grid::surface::SurfacePass;
use crate::voxel_grid::{self, VoxelGrid, VoxelizePass};

mod frames;
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
    /// Pass `voxel-surface`, made when the method reads the surface in the
    /// grid's cells (`Descriptor::reads_voxel_surface`).
    surface_pass: Option<SurfacePass>,
    /// The bounce passes (`bounce`), made when the method renders bounces
    /// and `--bounces` asks for more than one.
    bounce: Option<BouncePass>,
    /// Point lights' layered cube RSM (made only when the scene has one).
    rsm_cube: Option<CubeRsmPass>,
    method: Box<dyn IndirectMethod>,
    rsm: ScenePass,
    gbuffer: ScenePass,
    shadow: ShadowPass,
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
        let views = all_views(
            &state,
            &fitting,
            settings.rsm_resolution,
            settings.sun_shadow_fit(),
        );
        // The texture arrays' memory is checked with the rest before anything
        // is allocated; `SceneGpu::new` makes the same plan again (it is
        // cheap: sizes only).
        let textures = TexturePlan::new(&scene.textures)?.bytes();
        let descriptor = check_run(
            gpu,
            settings,
            &scene.lights,
            (views.len(), scene.instances.len()),
            textures,
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
        let contents = crate::methods::grid_contents(descriptor, settings);
        let voxel_grid = VoxelGrid::new(gpu, settings, contents)?;
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
            grid_surface: voxel_grid.surface.as_ref(),
        };
        let method = crate::methods::create(&setup)?;
        let rsm = rsm::new(&setup)?;
        let gbuffer = gbuffer::new(&setup)?;
        let shadow = ShadowPass::new(&setup)?;
        let direct = direct_light::new(&setup, &shadow.depth)?;
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
        let surface_pass = match &voxel_grid.surface {
            Some(surface) => Some(SurfacePass::new(&setup, surface)?),
            None => None,
        };
        let bounce = make_bounce(&setup, descriptor, views.len())?;
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
            surface_pass,
            bounce,
            rsm_cube,
            method,
            rsm,
            gbuffer,
            shadow,
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
        self.views = all_views(
            &self.state,
            &fitting,
            self.settings.rsm_resolution,
            self.settings.sun_shadow_fit(),
        );
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

    /// The voxel grid's surface sums (`voxel_grid::surface`), where the run
    /// has them.
    pub fn voxel_surface(&self) -> Option<&Buffer> {
        self.voxel_grid.surface.as_ref()
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
}

/// Checks `settings` for a run with `lights` (`views` RSMs, `instances`
/// transforms) and texture arrays of `textures` bytes on `gpu` before
/// anything is allocated: the shared sizes, the method's parameters and
/// checks, then the memory it all takes. Returns the method's descriptor.
fn check_run(
    gpu: &Gpu,
    settings: &RenderSettings,
    lights: &[crate::scene::Light],
    (views, instances): (usize, usize),
    textures: u64,
) -> Result<&'static dyn Descriptor> {
    check_ranges(settings)?;
    let d = crate::methods::check(settings)?;
    let method = crate::methods::memory(d, settings);
    check_settings(gpu, settings, method)?;
    check_textures(gpu, settings, method, textures)?;
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
        AddedMemory {
            method,
            cube_rsm,
            textures,
        },
    )?;
    Ok(d)
}

/// The bounce passes of a run of `d` made from `setup`, for frames of
/// `views` light views (`None` where it renders one bounce).
fn make_bounce(setup: &Setup, d: &dyn Descriptor, views: usize) -> Result<Option<BouncePass>> {
    match (
        crate::methods::renders_bounces(d, setup.settings),
        setup.grid_surface,
    ) {
        (true, Some(surface)) => BouncePass::new(setup, surface, views),
        _ => Ok(None),
    }
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
