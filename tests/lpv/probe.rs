//! The probe of `tests/lpv.rs`: method lpv made by hand on a renderer's
//! targets, so that a test can write the RSM and G-buffer it needs (a
//! single VPL in an empty volume) and read the method's grids back. Apart
//! from the tests because it is the harness they share, not a check.

use ash::vk;
use glam::{DVec3, IVec3, Vec3};
use isr::frame::{FrameContext, FrameSet, Samplers, Setup, Targets};
use isr::gpu_types::FrameUniforms;
use isr::methods::lpv::grid::{Cascade, Grid};
use isr::methods::lpv::{Layout, Lpv};
use isr::methods::IndirectMethod;
use isr::readback::{read_buffer, read_regions, Region};
use isr::renderer::Renderer;
use isr::scene::{Camera, Scene};
use isr::settings::RenderSettings;
use isr::vk::barrier::{self, Use};
use isr::vk::profiler::Profiler;
use isr::vk::{Buffer, Gpu, Image};

/// Picks one of the targets.
pub type Pick = fn(&Targets) -> &Image;

/// A point light of flux `flux` (W) at `position` with unit normal
/// `normal` (a Lambertian emitter), written into every RSM texel.
#[derive(Clone, Copy)]
pub struct Vpl {
    pub position: Vec3,
    pub normal: Vec3,
    pub flux: Vec3,
}

/// Method lpv made by hand on a renderer's targets: the renderer renders
/// the RSM and G-buffer of its scene (or the test writes them), then the
/// probe's own `Lpv` records its passes and the grids are read back.
///
/// Fields drop in declaration order: the probe's method and profiler first,
/// then what its descriptors name, the renderer's targets last (the reverse
/// of creation).
pub struct Probe<'g> {
    gpu: &'g Gpu,
    lpv: Lpv,
    profiler: Profiler,
    _samplers: Samplers,
    frame: FrameSet,
    _grid: Buffer,
    _run: Buffer,
    pub renderer: Renderer<'g>,
}

impl<'g> Probe<'g> {
    pub fn new(gpu: &'g Gpu, scene: &Scene, settings: &RenderSettings) -> Self {
        let renderer = Renderer::new(gpu, scene, settings).expect("renderer");
        let run = Buffer::with_data(
            gpu,
            "probe run uniforms",
            bytemuck::bytes_of(&renderer.run_uniforms()),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )
        .unwrap();
        let grid = isr::voxel_grid::VoxelGrid::new(gpu, settings, Default::default()).unwrap();
        let frame = FrameSet::new(gpu, &run, &grid.occupancy, scene.instances.len()).unwrap();
        let samplers = Samplers::new(gpu).unwrap();
        let lpv = Lpv::new(&Setup {
            gpu,
            frame: &frame.set,
            targets: &renderer.targets,
            samplers: &samplers,
            scene: &renderer.scene,
            settings,
            grid_surface: None,
        })
        .expect("lpv");
        Self {
            gpu,
            lpv,
            profiler: Profiler::new(gpu, 16).unwrap(),
            _samplers: samplers,
            frame,
            _grid: grid.occupancy,
            _run: run,
            renderer,
        }
    }

    pub fn layout(&self) -> Layout {
        self.lpv.layout()
    }

    /// Fills the targets `fills` pick with their values, then records the
    /// method's passes seen from `u`, and waits.
    pub fn run(&mut self, u: &FrameUniforms, fills: &[(Pick, [f32; 4])]) {
        self.frame.write(u, &[]);
        let (gpu, lpv, profiler) = (self.gpu, &self.lpv, &mut self.profiler);
        let (frame_set, r) = (self.frame.set.set, &self.renderer);
        gpu.run_once(|cmd| {
            profiler.begin_frame(gpu, cmd, false);
            for (pick, value) in fills {
                fill(gpu, cmd, pick(&r.targets), *value);
            }
            let ctx = FrameContext {
                gpu,
                cmd,
                frame_set,
                scene: &r.scene,
                targets: &r.targets,
            };
            lpv.record_eye_space(&ctx, profiler);
            lpv.record(&ctx, profiler, 0);
        })
        .unwrap();
    }

    /// The method on the renderer's scene: one frame rendered, then the
    /// probe's passes on its RSM and G-buffer. Returns the renderer's image.
    pub fn render(&mut self) -> isr::readback::Readback {
        self.renderer.render_frames(1, |_| {}).unwrap();
        let image = self.renderer.readback().unwrap();
        let u = self.renderer.frame_uniforms();
        self.run(&u, &[]);
        image
    }

    /// The method on `vpl` alone (every RSM texel holds a 1/R^2 share) and
    /// a G-buffer whose every pixel sees `surface` (point, normal).
    pub fn single(&mut self, u: &FrameUniforms, vpl: Vpl, surface: (Vec3, Vec3)) {
        let e = self.renderer.targets.rsm_flux.extent;
        let share = vpl.flux / (e.width * e.height) as f32;
        let fills: [(Pick, [f32; 4]); 5] = [
            (|t| &t.rsm_position, vpl.position.extend(1e-4).to_array()),
            (|t| &t.rsm_normal, vpl.normal.extend(1.0).to_array()),
            (|t| &t.rsm_flux, share.extend(0.0).to_array()),
            (|t| &t.gbuffer_position, surface.0.extend(1.0).to_array()),
            (|t| &t.gbuffer_normal, surface.1.extend(1.0).to_array()),
        ];
        self.run(u, &fills);
    }

    /// The propagated sum.
    pub fn sum(&self) -> Grid {
        Grid::from_planes(
            self.layout(),
            &read_buffer(self.gpu, self.lpv.sum()).unwrap(),
        )
    }

    /// Every layer of `images`, in layer order, one plane each.
    pub fn layers(&self, images: &[Image]) -> Vec<Vec<[f32; 4]>> {
        let mut regions = vec![];
        for (i, image) in images.iter().enumerate() {
            for l in 0..image.layers {
                regions.push(Region::layer(format!("{i}/{l}"), image, l));
            }
        }
        let mut read = read_regions(self.gpu, &regions).unwrap();
        images
            .iter()
            .enumerate()
            .map(|(i, image)| {
                (0..image.layers)
                    .flat_map(|l| read.rgba(&format!("{i}/{l}")).unwrap())
                    .collect()
            })
            .collect()
    }

    /// The injected SH.
    pub fn injected(&self) -> Grid {
        let [r, g, b]: [Vec<[f32; 4]>; 3] = self.layers(self.lpv.injected()).try_into().unwrap();
        Grid::from_layers(self.layout(), [r, g, b])
    }

    /// The geometry volumes (light, eye), with occlusion.
    pub fn geometry(&self) -> Option<[Vec<[f32; 4]>; 2]> {
        let g = self.lpv.geometry()?;
        Some(self.layers(g).try_into().unwrap())
    }

    /// The indirect image the probe's lookup wrote.
    pub fn indirect(&self) -> Vec<[f32; 4]> {
        let t = &self.renderer.targets;
        let mut read = read_regions(self.gpu, &[Region::color("indirect", &t.indirect)]).unwrap();
        read.rgba("indirect").unwrap()
    }
}

/// Clears mip 0 of `image` to `value` (a colour attachment), leaving it
/// read-only as a pass would.
fn fill(gpu: &Gpu, cmd: vk::CommandBuffer, image: &Image, value: [f32; 4]) {
    barrier::transition(
        gpu,
        cmd,
        &[image],
        Use::DISCARD_AFTER_READERS,
        Use::COLOR_ATTACHMENT,
    );
    let attachment = [vk::RenderingAttachmentInfo::default()
        .image_view(image.mip_views[0])
        .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue {
            color: vk::ClearColorValue { float32: value },
        })];
    let info = vk::RenderingInfo::default()
        .render_area(vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: image.extent,
        })
        .layer_count(1)
        .color_attachments(&attachment);
    unsafe {
        gpu.device.cmd_begin_rendering(cmd, &info);
        gpu.device.cmd_end_rendering(cmd);
    }
    barrier::transition(gpu, cmd, &[image], Use::COLOR_ATTACHMENT, Use::READ_ONLY);
}

/// The camera of the single-VPL tests: at the origin looking down -z, in
/// a scene 6 m wide around it (`SCENE_HALF`), so that with 32 cells the
/// cascades have cells of 1/16, 1/8 and 1/4 m (29 / 4 m is the smallest
/// power-of-two multiple of 29 cells at or above 6 m).
pub fn origin_camera(forward: Vec3) -> FrameUniforms {
    let camera = Camera::look_at(Vec3::ZERO, forward, Vec3::Y, 60f32.to_radians(), 0.05);
    FrameUniforms {
        camera_view_proj: isr::view::camera_view_proj(&camera, 32, 32).to_cols_array_2d(),
        camera_position: [0.0; 3],
        camera_forward: forward.to_array(),
        normal_depth_scale: 32768.0 / 8.0,
        scene_min: [-SCENE_HALF; 3],
        scene_max: [SCENE_HALF; 3],
        ..Default::default()
    }
}

/// Half the side of the scene `origin_camera` sees.
pub const SCENE_HALF: f32 = 3.0;

/// The VPL whose injection point (half a finest cell along its normal)
/// is the centre of cell `cell` of cascade 0.
pub fn vpl_at_centre(at: &Cascade, cell: IVec3, normal: Vec3, flux: Vec3) -> Vpl {
    let h = at.cell as f64;
    let centre = at.world(cell.as_dvec3() + DVec3::splat(0.5));
    Vpl {
        position: (centre - 0.5 * h * normal.as_dvec3()).as_vec3(),
        normal,
        flux,
    }
}
