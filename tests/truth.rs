//! The path-traced truth the bench measures against (docs/algorithm.md
//! section 6.6, `isr::bench::truth`): its noise estimate, the pixels it
//! compares, and that the dense reference meets it where nothing occludes
//! the light between surfaces and parts from it where something does.
mod common;

use common::*;
use isr::bench::truth::{trace, ShadowMaps};
use isr::bounces::Bounces;
use isr::scene::Scene;

/// The truths here are of one bounce, the bench's default.
const ONE: Bounces = Bounces::ONE;

/// The dense reference of `scene` against its truth at noise `target`:
/// (relative RMSE, the truth's spp and measured noise, fraction left out).
fn model_error(gpu: &isr::vk::Gpu, scene: &Scene, target: f64) -> (f64, u32, f64, f64) {
    let settings = sized("reference", 64, 64, 64);
    let r = render(gpu, scene, &settings, 1);
    let shadows = ShadowMaps::new(
        &r.light_views,
        r.origin,
        settings.shadow_size(),
        settings.pcf_radius,
    );
    let t = trace(scene, &r.readback, &shadows, target, 1, ONE, |_, _| {});
    let e = relative_rmse(&r.readback.indirect, &t.image.indirect, &t.mask.mask);
    (e, t.spp, t.noise, t.mask.left_out())
}

/// The truth's own noise, as it measures it from its two halves, is what
/// two truths of independent seeds differ by: each is off by its noise, so
/// they differ by sqrt(2) times it.
#[test]
fn the_truth_measures_its_own_noise() {
    let gpu = gpu();
    let scene = cornell_at_rest(true);
    let settings = sized("reference", 64, 64, 64);
    let r = render(&gpu, &scene, &settings, 1);
    let shadows = ShadowMaps::new(
        &r.light_views,
        r.origin,
        settings.shadow_size(),
        settings.pcf_radius,
    );
    let a = trace(&scene, &r.readback, &shadows, 0.1, 1, ONE, |_, _| {});
    let b = trace(&scene, &r.readback, &shadows, 0.1, 2, ONE, |_, _| {});
    let apart = relative_rmse(&a.image.indirect, &b.image.indirect, &a.mask.mask);
    let expected = (a.noise * a.noise + b.noise * b.noise).sqrt();
    println!(
        "truths at {} and {} spp, noise {:.4} and {:.4}: {apart:.4} apart, {expected:.4} expected",
        a.spp, b.spp, a.noise, b.noise
    );
    assert!(a.noise <= 0.1 && b.noise <= 0.1, "{} {}", a.noise, b.noise);
    assert!(
        (apart / expected - 1.0).abs() < 0.2,
        "{apart:.4} apart, {expected:.4} expected"
    );
}

/// In the box without its blocks every surface sees every other, so the
/// dense reference (which ignores indirect visibility) is off the truth by
/// its discretisation alone; with them, light the blocks hide is added
/// where the truth has none. Errors have the truth's noise taken out in
/// quadrature (it adds so to an error measured against it).
#[test]
fn the_dense_reference_meets_the_truth_where_nothing_occludes_and_parts_where_blocks_do() {
    let gpu = gpu();
    let target = 0.05;
    let [(open, open_noise), (blocked, blocked_noise)] = [false, true].map(|blocks| {
        let (e, spp, noise, left_out) = model_error(&gpu, &cornell_at_rest(blocks), target);
        let model = (e * e - noise * noise).max(0.0).sqrt();
        println!(
            "blocks {blocks}: {e:.4} from the truth ({spp} spp, noise {noise:.4}, \
             {:.0}% left out): model error {model:.4}",
            100.0 * left_out
        );
        assert!(noise <= target && left_out < 0.6, "{noise} {left_out}");
        (model, noise)
    });
    assert!(open < 0.03, "without blocks the reference is {open:.4} off");
    assert!(
        blocked > 0.08,
        "with blocks the reference is only {blocked:.4} off"
    );
    assert!(open_noise > 0.0 && blocked_noise > 0.0);
}
