//! The baselines of docs/algorithm.md section 5 compute the same sums in different
//! orders, on the same RSM, scene and composite.
mod common;

use common::*;
use isr::methods::{reference, rsm_splat};
use isr::multires::{DEPTH_THRESHOLD, NORMAL_THRESHOLD};
use isr::regular_vpls::VPLS;
use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::{Method, RenderSettings};

fn settings(method: Method) -> RenderSettings {
    RenderSettings {
        method,
        ..sized("none", 96, 80, 64)
    }
    .with(&VPLS, 64)
}

fn indirect_of(
    gpu: &isr::vk::Gpu,
    s: &RenderSettings,
) -> (Vec<[f32; 4]>, Vec<isr::vk::profiler::PassSample>) {
    let mut r = Renderer::new(gpu, &cornell_box(), s).unwrap();
    let stats = r.render_frames(1, |_| {}).unwrap();
    let out = r.readback().unwrap();
    drop(r);
    assert_validation_clean(gpu);
    (out.indirect, stats.frames.into_iter().next().unwrap())
}

/// Largest difference relative to the larger value (with a floor for zeros).
fn assert_same(name: &str, a: &[[f32; 4]], b: &[[f32; 4]], tolerance: f64) {
    let scale = b
        .iter()
        .flat_map(|p| &p[..3])
        .fold(0.0f64, |m, &v| m.max(v as f64));
    assert!(scale > 0.0, "{name}: the reference is black");
    // Most pixels are compared against light, not against black.
    let lit = b.iter().filter(|p| p[..3].iter().any(|&v| v > 0.0)).count();
    assert!(
        2 * lit >= b.len(),
        "{name}: only {lit} of {} reference pixels are lit",
        b.len()
    );
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        for k in 0..3 {
            let (x, y) = (x[k] as f64, y[k] as f64);
            assert!(
                (x - y).abs() <= tolerance * x.abs().max(y.abs()) + 1e-6 * scale,
                "{name}: pixel {i} channel {k}: {x} vs {y}"
            );
        }
    }
}

#[test]
fn rsm_gather_rsm_splat_and_level_zero_multires_gather_agree() {
    let gpu = gpu();
    let (gather, _) = indirect_of(&gpu, &settings(Method::new("rsm-gather")));
    let (splat, _) = indirect_of(&gpu, &settings(Method::new("rsm-splat")));
    let level_zero = settings(Method::new("multires-gather"))
        .with(&DEPTH_THRESHOLD, 0.0)
        .with(&NORMAL_THRESHOLD, 0.0);
    let (multires, _) = indirect_of(&gpu, &level_zero);
    assert_same("rsm-splat vs rsm-gather", &splat, &gather, 1e-5);
    assert_same(
        "multires-gather at level 0 vs rsm-gather",
        &multires,
        &gather,
        1e-5,
    );
}

/// A restricted splat leaves out a VPL only where its contribution is below
/// the threshold t (the quad covers the sphere where Phi / (pi d^2) >= t), so
/// per pixel and channel the full splats exceed the restricted ones by at
/// most N t, and never fall below them.
#[test]
fn restricted_splats_drop_at_most_n_times_the_threshold_per_pixel() {
    let gpu = gpu();
    let (full, full_stats) = indirect_of(&gpu, &settings(Method::new("rsm-splat")));
    let fragments = |s: &[isr::vk::profiler::PassSample]| {
        s.iter()
            .find(|p| p.name == "rsm-splat")
            .unwrap()
            .samples_passed
            .unwrap()
    };
    let n = VPLS.get(&settings(Method::new("rsm-splat"))) as f32;
    let mut previous = fragments(&full_stats);
    for t in [0.01f32, 0.05, 0.5] {
        let s = settings(Method::new("rsm-splat-restricted")).with(&rsm_splat::THRESHOLD, t);
        let (cut, cut_stats) = indirect_of(&gpu, &s);
        let shaded = fragments(&cut_stats);
        assert!(
            shaded < previous,
            "threshold {t}: {shaded} fragments, not fewer than {previous}"
        );
        previous = shaded;
        let mut largest_drop = 0.0f32;
        for (a, b) in cut.iter().zip(&full) {
            for k in 0..3 {
                let drop = b[k] - a[k];
                // Float sums in a different order: a relative 1e-5 slack.
                assert!(drop >= -1e-5 * b[k].abs() - 1e-9, "restricting added light");
                assert!(
                    drop <= n * t * (1.0 + 1e-5) + 1e-5 * b[k].abs(),
                    "threshold {t}: a pixel lost {drop} W/m^2, more than N t = {}",
                    n * t
                );
                largest_drop = largest_drop.max(drop);
            }
        }
        // The bound is not vacuous: something was dropped.
        assert!(largest_drop > 0.0, "threshold {t} dropped nothing");
    }
}

#[test]
fn multires_splat_equals_multires_gather() {
    let gpu = gpu();
    let (gather, _) = indirect_of(&gpu, &settings(Method::new("multires-gather")));
    let (splat, stats) = indirect_of(&gpu, &settings(Method::new("multires-splat")));
    assert_same("multires-splat vs multires-gather", &splat, &gather, 1e-5);
    assert!(stats.iter().any(|p| p.name == "splat"));
}

#[test]
fn reference_in_chunks_equals_rsm_gather_with_every_texel() {
    let gpu = gpu();
    let rsm = 32;
    let gather = RenderSettings {
        rsm_resolution: rsm,
        ..settings(Method::new("rsm-gather"))
    }
    .with(&VPLS, rsm * rsm);
    let reference = RenderSettings {
        rsm_resolution: rsm,
        ..settings(Method::new("reference"))
    }
    // 96 x 80 pixels x 100 VPLs per submission: 11 chunks for 1024 VPLs.
    .with(&reference::CHUNK, 96 * 80 * 100);
    let mut r = Renderer::new(&gpu, &cornell_box(), &reference).unwrap();
    let mut submissions = 0;
    let stats = r.render_frames(1, |p| submissions = p.submissions).unwrap();
    let chunked = r.readback().unwrap().indirect;
    drop(r);
    assert_validation_clean(&gpu);
    assert_eq!(submissions, 11, "one submission per chunk");
    let names: Vec<&str> = stats.frames[0].iter().map(|p| p.name).collect();
    assert_eq!(
        names.iter().filter(|n| **n == "reference").count(),
        1,
        "chunks are reported as one pass: {names:?}"
    );
    let (dense, _) = indirect_of(&gpu, &gather);
    assert_same(
        "reference vs rsm-gather with R^2 VPLs",
        &chunked,
        &dense,
        1e-5,
    );
}
