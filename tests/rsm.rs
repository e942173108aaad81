//! The reflective shadow map's radiometry (ALGORITHM.md section 2).
mod common;

use common::*;
use glam::Vec3;
use isr::renderer::RenderSettings;
use isr::scene::Camera;
use std::f64::consts::PI;

/// rho * integral of I(w) over the cone, by Simpson's rule in the polar angle.
fn expected_flux(light: &isr::scene::SpotLight, rho: f64) -> f64 {
    let n = 20_000;
    let b = light.outer_cone as f64;
    let h = b / n as f64;
    let f = |t: f64| light.intensity as f64 * light.angular_attenuation(t.cos()) * t.sin();
    let mut sum = f(0.0) + f(b);
    for k in 1..n {
        sum += f(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    rho * 2.0 * PI * sum * h / 3.0
}

#[test]
fn rsm_flux_sums_to_albedo_times_intensity_over_the_cone() {
    let gpu = gpu();
    let height = 1.0;
    let outer: f32 = 45.0;
    let light = spot(Vec3::new(0.0, height, 0.0), Vec3::ZERO, 7.0, 30.0, outer);
    let camera = Camera::look_at(
        Vec3::new(0.0, 3.0, 3.0),
        Vec3::ZERO,
        Vec3::Y,
        60f32.to_radians(),
        0.1,
    );
    let rho = 0.7;
    // The floor reaches past the RSM frustum on every side: every texel sees it.
    let scene = floor_scene(light, camera, 3.0, rho);
    let settings = RenderSettings {
        width: 64,
        height: 64,
        rsm_resolution: 256,
        ..Default::default()
    };
    let rsm = render(&gpu, &scene, &settings, 1).readback.rsm;
    // Every texel saw the floor (its solid angle is written wherever geometry
    // was rasterized); exactly the texels the cone lights are non-empty patches.
    assert!(
        rsm.flux.iter().all(|f| f[3] > 0.0),
        "some RSM texels saw no geometry"
    );
    for (n, f) in rsm.normal.iter().zip(&rsm.flux) {
        assert_eq!(
            n[3] == 1.0,
            f[0] > 0.0,
            "lit texels and only they are patches"
        );
    }

    let flux: f64 = rsm.flux.iter().map(|f| f[0] as f64).sum();
    let expected = expected_flux(&light, rho as f64);
    let rel = (flux - expected).abs() / expected;
    println!("RSM flux {flux:.6} W, expected {expected:.6} W (relative error {rel:.2e})");
    assert!(
        rel < 0.01,
        "RSM flux {flux} W vs rho * I * cone solid angle {expected} W"
    );

    // Solid angles: the texels tile the square frustum, 4 asin(sin^2 a).
    let a = (outer as f64).to_radians();
    let omega: f64 = rsm.flux.iter().map(|f| f[3] as f64).sum();
    let omega_expected = 4.0 * (a.sin() * a.sin()).asin();
    assert!(
        (omega - omega_expected).abs() < 0.01 * omega_expected,
        "sum of dw {omega} vs {omega_expected}"
    );

    // Areas: the lit texels tile the floor's disc under the cone, pi (h tan a)^2.
    let area: f64 = rsm.position.iter().map(|p| p[3] as f64).sum();
    let area_expected = std::f64::consts::PI * (height as f64 * a.tan()).powi(2);
    assert!(
        (area - area_expected).abs() < 0.01 * area_expected,
        "sum of A_j {area} vs {area_expected}"
    );
}
