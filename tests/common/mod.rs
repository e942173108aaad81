//! Helpers shared by the integration tests. Tests that need Vulkan fail with a
//! clear message when no device is found: they never skip, so a missing install
//! step shows up in CI.
#![allow(dead_code)]

use glam::{DVec3, Vec3, Vec4};
use isr::readback::Readback;
use isr::renderer::{FrameStats, Renderer};
use isr::scene::{Camera, Scene, SpotLight};
use isr::settings::RenderSettings;
use isr::vk::{Gpu, GpuOptions, Validation};

/// A device with the validation layer loaded when it is installed.
pub fn gpu() -> Gpu {
    match Gpu::new(&GpuOptions {
        validation: Validation::IfInstalled,
        device_index: None,
    }) {
        Ok(g) => g,
        Err(e) => panic!(
            "this test needs a Vulkan device and found none usable: {e:#}\n\
             Run `bash .ci/install-vulkan` (installs Mesa's lavapipe) and try again."
        ),
    }
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

pub struct Rendered {
    pub readback: Readback,
    pub stats: FrameStats,
    pub uniforms: isr::gpu_types::FrameUniforms,
}

/// Renders `frames` frames of `scene` and reads the results back, checking
/// that validation stayed silent.
pub fn render(gpu: &Gpu, scene: &Scene, settings: &RenderSettings, frames: u32) -> Rendered {
    let mut r = Renderer::new(gpu, scene, settings).expect("renderer setup");
    let stats = r.render_frames(frames, |_| {}).expect("rendering");
    let readback = r.readback().expect("readback");
    let uniforms = r.frame_uniforms();
    drop(r);
    assert_validation_clean(gpu);
    Rendered {
        readback,
        stats,
        uniforms,
    }
}

/// The pixel (x, y) where world point `p` lands, if it is on screen.
pub fn project(
    u: &isr::gpu_types::FrameUniforms,
    width: u32,
    height: u32,
    p: Vec3,
) -> Option<(u32, u32)> {
    let m = glam::Mat4::from_cols_array_2d(&u.camera_view_proj);
    let c = m * p.extend(1.0);
    if c.w <= 0.0 {
        return None;
    }
    let ndc = c.truncate() / c.w;
    let x = ((ndc.x * 0.5 + 0.5) * width as f32).floor();
    let y = ((ndc.y * 0.5 + 0.5) * height as f32).floor();
    (x >= 0.0 && y >= 0.0 && x < width as f32 && y < height as f32).then_some((x as u32, y as u32))
}

/// A spot light at `position` aimed at `target`.
pub fn spot(
    position: Vec3,
    target: Vec3,
    intensity: f32,
    inner_deg: f32,
    outer_deg: f32,
) -> SpotLight {
    SpotLight {
        kind: isr::scene::LightKind::Spot,
        position,
        direction: (target - position).normalize(),
        color: Vec3::ONE,
        intensity,
        inner_cone: inner_deg.to_radians(),
        outer_cone: outer_deg.to_radians(),
        range: None,
    }
}

/// A scene with one horizontal square floor of half-size `half` at y = 0.
pub fn floor_scene(light: SpotLight, camera: Camera, half: f32, albedo: f32) -> Scene {
    let mut s = Scene::empty("floor", light, camera);
    let m = s.add_material("floor", Vec3::splat(albedo));
    let v = Vec3::new;
    s.add_quad(
        "floor",
        [
            v(-half, 0., half),
            v(half, 0., half),
            v(half, 0., -half),
            v(-half, 0., -half),
        ],
        m,
    );
    s
}

/// The direct radiance docs/algorithm.md section 2 gives for an unshadowed
/// Lambertian point: rho/pi * I(w) * max(0, n.l) / r^2, per channel, in f64.
pub fn expected_direct(light: &SpotLight, albedo: Vec4, p: DVec3, n: DVec3) -> DVec3 {
    let to_light = light.position.as_dvec3() - p;
    let r2 = to_light.length_squared();
    let cos = n.dot(to_light / r2.sqrt()).max(0.0);
    albedo.truncate().as_dvec3() / std::f64::consts::PI * light.intensity_toward(p) * cos / r2
}

/// Expects `out` (a run of the `isr` binary for `args`) to have failed with
/// an `error:` message and no panic; returns its stderr.
pub fn clean_failure(out: &std::process::Output, args: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        !out.status.success(),
        "expected failure for {args:?}; stderr:\n{stderr}"
    );
    assert!(
        !stderr.contains("panicked") && !stderr.contains("RUST_BACKTRACE"),
        "panic for {args:?}:\n{stderr}"
    );
    assert!(
        stderr.contains("error:"),
        "no error message for {args:?}:\n{stderr}"
    );
    println!("{args:?}:\n{stderr}");
    stderr
}

pub fn bin() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_isr"))
}

pub struct RenderedMultires {
    pub readback: Readback,
    pub multires: isr::readback::MultiresReadback,
    pub stats: FrameStats,
    pub uniforms: isr::gpu_types::FrameUniforms,
    pub run: isr::gpu_types::RunUniforms,
    pub total_area: u64,
}

/// Renders with a multiresolution method and reads back its buffer too.
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

/// The regular VPLs of RSM quadtree level `k` as (position, normal, flux, area).
pub fn vpls_at(m: &isr::readback::MultiresReadback, k: usize) -> Vec<(DVec3, DVec3, DVec3, f64)> {
    let [pos, nrm, flux] = &m.rsm_tree[k];
    pos.iter()
        .zip(nrm)
        .zip(flux)
        .filter(|((p, _), _)| p[3] > 0.0)
        .map(|((p, n), f)| {
            let v = |a: &[f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
            (v(p), v(n), v(f), p[3] as f64)
        })
        .collect()
}

/// docs/algorithm.md section 2 in f64: sum over patches of
/// Phi_j cos_i cos_j / (pi d^2 + A_j), the irradiance at (x, n).
pub fn cpu_gather(vpls: &[(DVec3, DVec3, DVec3, f64)], x: DVec3, n: DVec3) -> DVec3 {
    let mut e = DVec3::ZERO;
    for &(xj, nj, phi, a) in vpls {
        let v = xj - x;
        let d2 = v.length_squared();
        let dir = v / d2.sqrt().max(1e-15);
        let cos_i = n.dot(dir).max(0.0);
        let cos_j = (-nj.dot(dir)).max(0.0);
        e += phi * (cos_i * cos_j / (std::f64::consts::PI * d2 + a));
    }
    e
}

pub fn dvec(a: &[f32; 4]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}
