//! The integration tests' one kit: devices (`gpu`, `validating_gpu`),
//! rendering and reading back (`render`, `render_multires`), the scenes and
//! lights the tests build, the expected direct light written out from
//! KHR_lights_punctual (not the library's own `Light` methods), CPU sums,
//! and the bench's error measures (`isr::bench::metrics`). Submodules:
//! `cli`, the one runner of the `isr` binary; `court`, the sun-lit court of
//! the shadow tests; `sibenik`, the Sibenik nave of the shadow tests;
//! `gltf`, the one builder of
//! glTF and GLB files; `grid`, the voxel visibility settings and the grid
//! read back; `measure`, work counted on this thread (allocations,
//! bytes read).
//!
//! Tests that need Vulkan fail with a clear message when no device is found:
//! they never skip, so a missing install step shows up in CI.
#![allow(dead_code)]

pub mod black_walls;
pub mod cli;
pub mod court;
pub mod framing;
pub mod gltf;
pub mod grid;
pub mod measure;
pub mod sibenik;
pub mod sphere;
pub mod traced;

// Every test binary compiles this kit; most use no grid helper.
#[allow(unused_imports)]
pub use grid::*;

use glam::{DVec3, Vec3};
use isr::readback::Readback;
use isr::renderer::{FrameStats, Renderer};
use isr::scene::{cornell::cornell_box, Camera, Light, LightKind, Scene};
use isr::settings::{Method, RenderSettings};
use isr::vk::{Gpu, GpuOptions, Validation};

pub use isr::bench::metrics::{geometry_mask, relative_rmse};

/// Relative RMSE of indirect radiance `x` against the path-traced truth `t`
/// over its mask, with the truth's own noise taken out in quadrature
/// (`Truth::model_error`).
pub fn model_error(x: &[[f32; 4]], t: &isr::bench::truth::Truth) -> f64 {
    t.model_error(x)
}

// Devices.

/// Held while a test thread creates or destroys its device. Each test makes
/// its own instance and device, and the test harness runs them on parallel
/// threads; creation and destruction are where the loader, the layer and
/// the driver touch process-wide state (layer libraries, Mesa's shared
/// compiler state), and CI once saw `tests/lpv.rs` die of SIGSEGV with two
/// tests in flight (not reproduced here in 45 runs, nor with memcheck, which
/// was clean). Measured with the turns taken: `tests/lpv.rs` runs in about
/// 6.2 s at 2 threads and the whole suite in about 2m49s here; work between
/// creation and destruction still overlaps.
static DEVICE_LIFETIMES: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn device_turn() -> std::sync::MutexGuard<'static, ()> {
    // A test that panicked while holding it left nothing half-made.
    DEVICE_LIFETIMES
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A test's device: a `Gpu` (through `Deref`) whose creation and
/// destruction take their turn with other threads' (`DEVICE_LIFETIMES`).
pub struct TestGpu(Option<Gpu>);

impl std::ops::Deref for TestGpu {
    type Target = Gpu;
    fn deref(&self) -> &Gpu {
        self.0.as_ref().expect("the device lives until drop")
    }
}

impl Drop for TestGpu {
    fn drop(&mut self) {
        let _turn = device_turn();
        drop(self.0.take());
    }
}

fn test_gpu(validation: Validation) -> anyhow::Result<TestGpu> {
    let _turn = device_turn();
    Gpu::new(&GpuOptions {
        validation,
        device_index: None,
    })
    .map(|gpu| TestGpu(Some(gpu)))
}

/// A device with the validation layer loaded when it is installed.
pub fn gpu() -> TestGpu {
    test_gpu(Validation::IfInstalled).unwrap_or_else(|e| {
        panic!(
            "this test needs a Vulkan device and found none usable: {e:#}\n\
             Run `bash .ci/install-vulkan` (installs Mesa's lavapipe) and try again."
        )
    })
}

/// A device with the Khronos validation layer, which the test needs.
pub fn validating_gpu() -> TestGpu {
    test_gpu(Validation::Required).unwrap_or_else(|e| {
        panic!(
            "{e:#}\nThis test needs the Khronos validation layer: \
             run `bash .ci/install-vulkan --validation`."
        )
    })
}

/// Fails the test if the validation layer reported anything.
pub fn assert_validation_clean(gpu: &Gpu) {
    let messages = gpu.take_validation_messages();
    assert!(
        messages.is_empty(),
        "the validation layer reported {} message(s):\n{}",
        messages.len(),
        messages.join("\n")
    );
}

// Rendering.

/// `method` at `width` x `height` with an RSM of `rsm` in the paper's model
/// (`--visibility none`: the CPU sums the tests hold the GPU to have no
/// occlusion; a test of the grid sets it; one bounce, as the paper's and
/// the sums': a test of bounces sets them), every other setting the default.
pub fn sized(method: &'static str, width: u32, height: u32, rsm: u32) -> RenderSettings {
    RenderSettings {
        width,
        height,
        rsm_resolution: rsm,
        method: Method::new(method),
        ..Default::default()
    }
    .with(
        &isr::visibility::VISIBILITY,
        isr::visibility::Visibility::None,
    )
    .with(&isr::bounces::BOUNCES, isr::bounces::Bounces::ONE)
}

/// `s` with the parameters that set the cost of its method made small, only
/// where the method reads them: `vpls` VPLs, an ISR base of `isr_base`, and
/// reference chunks of `chunk` pixel-VPLs per submission.
pub fn small_params(mut s: RenderSettings, vpls: u32, isr_base: u32, chunk: u64) -> RenderSettings {
    use isr::methods::{isr::BASE, reference::CHUNK};
    use isr::regular_vpls::VPLS;
    let method = isr::methods::find(s.method).expect("a registered method");
    for p in isr::methods::params_of(method) {
        match p.name() {
            n if n == VPLS.name => VPLS.set(&mut s, vpls),
            n if n == BASE.name => BASE.set(&mut s, isr_base),
            n if n == CHUNK.name => CHUNK.set(&mut s, chunk),
            _ => {}
        }
    }
    s
}

pub struct Rendered {
    pub readback: Readback,
    pub stats: FrameStats,
    /// As the GPU saw them: positions relative to `origin`.
    pub uniforms: isr::gpu_types::FrameUniforms,
    /// The render origin (`isr::scene::render_origin`).
    pub origin: glam::DVec3,
    /// The RSMs of the last frame (matrices relative to `origin`).
    pub light_views: Vec<isr::view::LightView>,
}

/// Renders `frames` frames of `scene` and reads the results back, checking
/// that validation stayed silent.
pub fn render(gpu: &Gpu, scene: &Scene, settings: &RenderSettings, frames: u32) -> Rendered {
    let mut r = Renderer::new(gpu, scene, settings).expect("renderer setup");
    let stats = r.render_frames(frames, |_| {}).expect("rendering");
    let readback = r.readback().expect("readback");
    let uniforms = r.frame_uniforms();
    let origin = r.render_origin();
    let light_views = r.light_views().to_vec();
    drop(r);
    assert_validation_clean(gpu);
    Rendered {
        readback,
        stats,
        uniforms,
        origin,
        light_views,
    }
}

pub struct RenderedMultires {
    pub readback: Readback,
    pub multires: isr::readback::MultiresReadback,
    pub stats: FrameStats,
    pub uniforms: isr::gpu_types::FrameUniforms,
    pub run: isr::gpu_types::RunUniforms,
    pub total_area: u64,
}

/// Renders one frame with a multiresolution method and reads back its
/// buffer too.
pub fn render_multires(gpu: &Gpu, scene: &Scene, settings: &RenderSettings) -> RenderedMultires {
    let mut r = Renderer::new(gpu, scene, settings).expect("renderer setup");
    let stats = r.render_frames(1, |_| {}).expect("rendering");
    let readback = r.readback().expect("readback");
    let multires = r
        .readback_multires()
        .expect("readback")
        .expect("a multiresolution method");
    let uniforms = r.frame_uniforms();
    let run = r.run_uniforms();
    let total_area = r.multires().expect("a multiresolution method").total_area();
    drop(r);
    assert_validation_clean(gpu);
    RenderedMultires {
        readback,
        multires,
        stats,
        uniforms,
        run,
        total_area,
    }
}

/// The pixel (x, y) of `r` where world point `p` lands, if it is on screen.
pub fn project(r: &Rendered, p: Vec3) -> Option<(u32, u32)> {
    let (width, height) = (r.readback.width, r.readback.height);
    let m = glam::Mat4::from_cols_array_2d(&r.uniforms.camera_view_proj);
    let c = m * (p.as_dvec3() - r.origin).as_vec3().extend(1.0);
    if c.w <= 0.0 {
        return None;
    }
    let ndc = c.truncate() / c.w;
    let x = ((ndc.x * 0.5 + 0.5) * width as f32).floor();
    let y = ((ndc.y * 0.5 + 0.5) * height as f32).floor();
    (x >= 0.0 && y >= 0.0 && x < width as f32 && y < height as f32).then_some((x as u32, y as u32))
}

/// Relative RMSE of `x`'s indirect image against `reference`'s over the
/// reference's pixels with geometry (`isr::bench::metrics`).
pub fn indirect_rmse(x: &Readback, reference: &Readback) -> f64 {
    relative_rmse(
        &x.indirect,
        &reference.indirect,
        &geometry_mask(&reference.position),
    )
}

/// Pixels with geometry in `r` (G-buffer position w > 0).
pub fn geometry_pixels(r: &Readback) -> usize {
    geometry_mask(&r.position).iter().filter(|&&g| g).count()
}

/// One `#[test]` per kind of light, each calling `$check(kind)`:
/// `light_kind_tests!(check: spot_test, point_test, directional_test);`.
#[allow(unused_macros)]
macro_rules! light_kind_tests {
    ($check:ident: $spot:ident, $point:ident, $directional:ident) => {
        #[test]
        fn $spot() {
            $check(isr::scene::LightKind::Spot);
        }

        #[test]
        fn $point() {
            $check(isr::scene::LightKind::Point);
        }

        #[test]
        fn $directional() {
            $check(isr::scene::LightKind::Directional);
        }
    };
}
#[allow(unused_imports)]
pub(crate) use light_kind_tests;

// Lights and scenes.

fn light(kind: LightKind, position: Vec3, direction: Vec3, intensity: f32) -> Light {
    Light {
        kind,
        position,
        direction: direction.normalize(),
        color: Vec3::ONE,
        intensity,
        inner_cone: 0.0,
        outer_cone: std::f32::consts::FRAC_PI_2,
        range: None,
    }
}

/// A spot light at `position` aimed at `target`, cones in degrees.
pub fn spot(position: Vec3, target: Vec3, intensity: f32, inner_deg: f32, outer_deg: f32) -> Light {
    Light {
        inner_cone: inner_deg.to_radians(),
        outer_cone: outer_deg.to_radians(),
        ..light(LightKind::Spot, position, target - position, intensity)
    }
}

/// A point light of `intensity` W/sr.
pub fn point(position: Vec3, intensity: f32) -> Light {
    light(LightKind::Point, position, -Vec3::Y, intensity)
}

/// A directional light giving `irradiance` W/m^2 to a surface facing it.
pub fn sun(direction: Vec3, irradiance: f32) -> Light {
    light(LightKind::Directional, Vec3::ZERO, direction, irradiance)
}

/// The point light the several-lights tests hang in the Cornell box.
pub fn box_point() -> Light {
    point(Vec3::new(0.3, 1.3, 0.2), 2.0)
}

/// The directional light of the several-lights tests: through the ceiling,
/// which faces down and so is culled from the RSM (as single-sided faces
/// turned away from a light are).
pub fn box_sun() -> Light {
    sun(Vec3::new(0.4, -1.0, -0.3), 1.5)
}

/// The Cornell box, still, lit by `lights`.
/// A horizontal disc of radius `r` at height `y`, centred on the y axis,
/// of material `m` (the visibility tests' occluder).
pub fn disc(s: &mut Scene, m: usize, y: f32, r: f32) {
    let segments = 64;
    let vertex = |p: Vec3| isr::scene::GpuVertex {
        position: p.to_array(),
        normal: [0.0, 1.0, 0.0],
        uv: [0.0; 2],
    };
    let mut v = vec![vertex(Vec3::new(0.0, y, 0.0))];
    let mut i = vec![];
    for k in 0..segments {
        let a = k as f32 / segments as f32 * std::f32::consts::TAU;
        v.push(vertex(Vec3::new(r * a.cos(), y, r * a.sin())));
        i.extend([0, 1 + k, 1 + (k + 1) % segments]);
    }
    s.add_mesh("disc", v, i, m);
}

/// A VPL at `p` facing down (the visibility tests' light).
pub fn down(p: Vec3, flux: f32) -> isr::exact_visibility::Vpl {
    isr::exact_visibility::Vpl {
        position: p,
        normal: -Vec3::Y,
        flux: Vec3::splat(flux),
        area: 1e-4,
    }
}

/// The built-in box at rest with its blocks, or without them (a convex
/// room: every surface sees every other, so visibility changes nothing).
pub fn cornell_at_rest(blocks: bool) -> Scene {
    let mut s = cornell_box();
    s.animation = None;
    if !blocks {
        let keep: Vec<bool> = s
            .meshes
            .iter()
            .map(|m| !m.name.ends_with("block"))
            .collect();
        s.instances.retain(|i| keep[i.mesh]);
    }
    s
}

pub fn cornell_with(lights: Vec<Light>) -> Scene {
    let mut s = cornell_box();
    s.animation = None;
    s.lights = lights;
    s
}

/// A camera 6 m above the origin looking straight down.
pub fn looking_down() -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 6.0, 0.0),
        Vec3::ZERO,
        -Vec3::Z,
        70f32.to_radians(),
        0.1,
    )
}

/// The corners of a horizontal square of half-size `half` centred on `c`,
/// facing up (+y); reversed, it faces down.
pub fn square(c: Vec3, half: f32) -> [Vec3; 4] {
    [
        c + Vec3::new(-half, 0.0, half),
        c + Vec3::new(half, 0.0, half),
        c + Vec3::new(half, 0.0, -half),
        c + Vec3::new(-half, 0.0, -half),
    ]
}

/// Adds an upward-facing square of grey `albedo` to `s`.
pub fn add_square(s: &mut Scene, name: &str, c: Vec3, half: f32, albedo: f32) {
    let m = s.add_material(name, Vec3::splat(albedo));
    s.add_quad(name, square(c, half), m);
}

/// A scene with one horizontal square floor of half-size `half` at y = 0.
pub fn floor_scene(light: Light, camera: Camera, half: f32, albedo: f32) -> Scene {
    let mut s = Scene::empty("floor", light, camera);
    add_square(&mut s, "floor", Vec3::ZERO, half, albedo);
    s
}

/// Index of the instance whose rest transform puts the mesh's origin at `x`.
pub fn instance_at(s: &Scene, x: f32) -> usize {
    s.instances
        .iter()
        .position(|i| (i.world_from_object.w_axis.x - x).abs() < 1e-6)
        .unwrap()
}

/// A floor (half-size 3, grey 0.5) under a spot light 2 m above it, seen
/// from the side, with a single-sided square occluder (half-size 0.2, at
/// 1 m) facing the light or, reversed, facing away from it. Facing the
/// light, it shadows |x|, |z| < 0.4 on the floor.
pub fn spot_over_an_occluder(facing_light: bool) -> Scene {
    let light = spot(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, 10.0, 40.0, 50.0);
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.5, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        50f32.to_radians(),
        0.1,
    );
    let mut s = floor_scene(light, camera, 3.0, 0.5);
    let m = s.add_material("occluder", Vec3::splat(0.5));
    let mut corners = square(Vec3::new(0.0, 1.0, 0.0), 0.2);
    if !facing_light {
        corners.reverse();
    }
    s.add_quad("occluder", corners, m);
    s
}

/// Asserts that light 0 and the camera of two frame states agree: light
/// positions and directions within `light_tol`, camera matrices within
/// `camera_tol`.
pub fn assert_light_and_camera_agree(
    a: &isr::scene::FrameState,
    b: &isr::scene::FrameState,
    light_tol: f32,
    camera_tol: f32,
    what: &str,
) {
    let (la, lb) = (&a.lights[0], &b.lights[0]);
    assert!(
        la.position.abs_diff_eq(lb.position, light_tol)
            && la.direction.abs_diff_eq(lb.direction, light_tol),
        "{what}: light {la:?} vs {lb:?}"
    );
    assert!(
        a.camera
            .world_from_camera
            .abs_diff_eq(b.camera.world_from_camera, camera_tol),
        "{what}: camera {:?} vs {:?}",
        a.camera,
        b.camera
    );
}

// The expected direct light, from KHR_lights_punctual written out here.

/// The extension's smooth cone falloff for a spot light at `cos_angle` off its
/// axis: `t = clamp(cos * scale + offset, 0, 1)`, `t^2`, with
/// `scale = 1 / max(0.001, cos inner - cos outer)` and
/// `offset = -cos outer * scale`; 1 for point and directional lights.
pub fn khr_cone_attenuation(light: &Light, cos_angle: f64) -> f64 {
    if light.kind != LightKind::Spot {
        return 1.0;
    }
    let cos_outer = (light.outer_cone as f64).cos();
    let cos_inner = (light.inner_cone as f64).cos();
    let scale = 1.0 / (cos_inner - cos_outer).max(0.001);
    let offset = -cos_outer * scale;
    let t = (cos_angle * scale + offset).clamp(0.0, 1.0);
    t * t
}

/// What a spot or point light loses toward `p` beyond `1 / d^2`: the cone's
/// falloff (spot lights) times the range window `clamp(1 - (d / range)^4,
/// 0, 1)` when a range is set; 1 for directional lights.
pub fn khr_attenuation(light: &Light, p: DVec3) -> f64 {
    if light.kind == LightKind::Directional {
        return 1.0;
    }
    let from_light = p - light.position.as_dvec3();
    let d = from_light.length();
    let axis = light.direction.as_dvec3().normalize();
    let mut a = khr_cone_attenuation(light, from_light.dot(axis) / d);
    if let Some(range) = light.range {
        a *= (1.0 - (d / range as f64).powi(4)).clamp(0.0, 1.0);
    }
    a
}

/// Irradiance (W/m^2 per channel) at `p` on a surface with normal `n`,
/// unshadowed: `I khr_attenuation cos / d^2` for spot and point lights,
/// `E cos` for directional ones.
pub fn khr_irradiance(light: &Light, p: DVec3, n: DVec3) -> DVec3 {
    let color = light.color.as_dvec3() * light.intensity as f64;
    if light.kind == LightKind::Directional {
        let to_light = -light.direction.as_dvec3().normalize();
        return color * n.dot(to_light).max(0.0);
    }
    let to_light = light.position.as_dvec3() - p;
    let d2 = to_light.length_squared();
    let cos = n.dot(to_light / d2.sqrt()).max(0.0);
    color * khr_attenuation(light, p) * cos / d2
}

/// Direct radiance of an unshadowed Lambertian point of grey `albedo`
/// (docs/algorithm.md section 2): `rho / pi` times `khr_irradiance`.
pub fn expected_direct(light: &Light, albedo: f64, p: DVec3, n: DVec3) -> DVec3 {
    khr_irradiance(light, p, n) * albedo / std::f64::consts::PI
}

// CPU sums.

pub fn dvec(a: &[f32; 4]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

/// A light patch for [`cpu_gather`]: position, unit normal, flux, area and
/// its level as `patch_level` (shaders/shared.glsl) gives it.
pub type CpuVpl = (DVec3, DVec3, DVec3, f64, i32);

/// `patch_level` of shaders/shared.glsl: level `k`, negated when the
/// patch's state (normal.w) says it spans a discontinuity.
pub fn patch_level(k: usize, state: f32) -> i32 {
    if state == isr::gpu_types::PATCH_INVALID {
        -(k as i32)
    } else {
        k as i32
    }
}

/// The regular VPLs of RSM quadtree level `k`.
pub fn vpls_at(m: &isr::readback::MultiresReadback, k: usize) -> Vec<CpuVpl> {
    let [pos, nrm, flux] = &m.rsm_tree[k];
    pos.iter()
        .zip(nrm)
        .zip(flux)
        .filter(|((p, _), _)| p[3] > 0.0)
        .map(|((p, n), f)| (dvec(p), dvec(n), dvec(f), p[3] as f64, patch_level(k, n[3])))
        .collect()
}

/// docs/algorithm.md section 2.6 in f64, with the default second-order
/// kernel for merged patches on one surface (level > 0): the irradiance
/// at (x, n) from `vpls`.
pub fn cpu_gather(vpls: &[CpuVpl], x: DVec3, n: DVec3) -> DVec3 {
    let mut e = DVec3::ZERO;
    for &(xj, nj, phi, a, level) in vpls {
        let v = xj - x;
        let d2 = v.length_squared();
        let dir = v / d2.sqrt().max(1e-15);
        let cos_i = n.dot(dir).max(0.0);
        let cos_j = (-nj.dot(dir)).max(0.0);
        let denominator = std::f64::consts::PI * d2 + a;
        let mut k = cos_i * cos_j / denominator;
        if level > 0 && k > 0.0 {
            let f = a / denominator;
            let second = cos_i * cos_j * (1.0 + f * (2.0 - 3.0 * cos_j * cos_j))
                - f * cos_j * cos_j * n.dot(nj);
            k = (second / denominator).clamp(0.0, 1.0 / denominator);
        }
        e += phi * k;
    }
    e
}

/// A fresh empty folder under the system temp dir, for one test's files.
pub fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("isr-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
