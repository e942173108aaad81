//! A sun's shadow map fitted to what the camera sees (docs/algorithm.md
//! section 2.2) holds still as the camera moves: its texels are snapped to
//! a grid fixed to the scene, so direct light does not shimmer. Against the
//! path tracer's exact direct light, frame by frame along a camera orbit,
//! the error's frame-to-frame change (section 6.3's flicker, per pixel) is
//! no larger than with the shadow map fixed on the whole scene (the RSM's
//! square, which cannot shimmer), and the error itself is smaller.
mod common;

use common::*;
use glam::Vec3;
use isr::scene::{cuboid, Camera, Scene};

/// A 40 m ground with a few blocks, under a low sun, seen from `eye`
/// looking at the middle block: the view spans a few metres of the 40.
fn yard(eye: Vec3) -> Scene {
    let camera = Camera::look_at(
        eye,
        Vec3::new(0.0, 0.3, 0.0),
        Vec3::Y,
        50f32.to_radians(),
        0.05,
    );
    let mut s = Scene::empty("yard", sun(Vec3::new(1.0, -0.55, 0.4), 3.0), camera);
    let grey = s.add_material("grey", Vec3::splat(0.6));
    s.add_quad("ground", square(Vec3::ZERO, 20.0), grey);
    for (k, (c, size, turn)) in [
        (Vec3::new(0.0, 0.4, 0.0), 0.8, 0.4),
        (Vec3::new(-1.5, 0.3, 1.0), 0.6, 1.1),
        (Vec3::new(1.2, 0.25, -1.3), 0.5, 0.2),
    ]
    .into_iter()
    .enumerate()
    {
        let (v, i) = cuboid(c, Vec3::splat(size), turn);
        s.add_mesh(&format!("block {k}"), v, i, grey);
    }
    s
}

/// Direct light of `scene` at `n` x `n`, the fitted or the fixed shadow
/// map of `size`, minus the path tracer's, and the path tracer's; pixels
/// without geometry are zero in both.
fn error_and_truth(
    gpu: &isr::vk::Gpu,
    scene: &Scene,
    n: u32,
    size: u32,
    fit: bool,
) -> (Vec<f32>, Vec<f32>) {
    let settings = isr::settings::RenderSettings {
        shadow_resolution: size,
        fit_sun_shadow: fit,
        ..sized("none", n, n, 64)
    };
    let raster = render(gpu, scene, &settings, 1).readback;
    let traced = common::traced::traced_once(scene, n, n);
    (0..(n * n) as usize)
        .map(|k| {
            let seen = raster.position[k][3] > 0.0;
            let (r, t) = (raster.direct[k][0], traced.direct[k][0]);
            if seen {
                (r - t, t)
            } else {
                (0.0, 0.0)
            }
        })
        .unzip()
}

#[test]
fn a_fitted_sun_shadow_does_not_shimmer_as_the_camera_orbits() {
    let gpu = gpu();
    let (n, size) = (96, 512);
    // Eight steps of 1.5 degrees around the middle block, 4 m off.
    let eyes: Vec<Vec3> = (0..8)
        .map(|k| {
            let a = (30.0 + 1.5 * k as f32).to_radians();
            Vec3::new(4.0 * a.cos(), 2.2, 4.0 * a.sin())
        })
        .collect();
    let mut measures = vec![];
    for fit in [true, false] {
        let frames: Vec<(Vec<f32>, Vec<f32>)> = eyes
            .iter()
            .map(|&eye| error_and_truth(&gpu, &yard(eye), n, size, fit))
            .collect();
        let sq = |v: &[f32]| v.iter().map(|&x| (x as f64) * (x as f64)).sum::<f64>();
        let truth = frames.iter().map(|(_, t)| sq(t)).sum::<f64>() / frames.len() as f64;
        let change = frames
            .windows(2)
            .map(|w| {
                let d: Vec<f32> = w[1].0.iter().zip(&w[0].0).map(|(a, b)| a - b).collect();
                sq(&d)
            })
            .sum::<f64>()
            / (frames.len() - 1) as f64;
        let error = frames.iter().map(|(e, _)| sq(e)).sum::<f64>() / frames.len() as f64;
        let flicker = (change / truth).sqrt();
        let rmse = (error / truth).sqrt();
        println!("fitted {fit}: flicker {flicker:.4}, error {rmse:.4}");
        measures.push((flicker, rmse));
    }
    let ((fitted_flicker, fitted_error), (fixed_flicker, fixed_error)) = (measures[0], measures[1]);
    // Both include the pixel-scale change the orbit itself brings (edges
    // crossing pixels), the same for both; a shadow grid sliding with the
    // view would add to the fitted one. A 5% margin for that shared part's
    // noise.
    assert!(
        fitted_flicker <= 1.05 * fixed_flicker,
        "fitted {fitted_flicker:.4} against fixed {fixed_flicker:.4}"
    );
    // The fitted map's texels are several times finer here: less error.
    assert!(
        fitted_error < fixed_error,
        "fitted {fitted_error:.4} against fixed {fixed_error:.4}"
    );
}
