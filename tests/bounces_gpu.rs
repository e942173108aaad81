//! Bounces 2..N on the GPU (docs/algorithm.md section 5.9, "Multiple
//! bounces"): the shared bounce passes against the closed sphere's exact
//! answer, against the path-traced truth of as many bounces in the box,
//! `--bounces 1` left as it was, and every method that renders bounces
//! validation-clean with them.
mod common;

use common::sphere::{series, sphere, spot_power};
use common::*;
use glam::DVec3;
use isr::bench::truth::{trace, ShadowMaps};
use isr::bounces::{Bounces, BOUNCES};
use isr::settings::RenderSettings;
use isr::visibility::{Visibility, VISIBILITY};

fn with_bounces(s: &RenderSettings, n: Bounces) -> RenderSettings {
    s.clone().with(&BOUNCES, n)
}

/// The mean indirect irradiance over the pixels with geometry.
fn mean_indirect(r: &Rendered) -> DVec3 {
    let rb = &r.readback;
    let seen: Vec<DVec3> = (0..rb.indirect.len())
        .filter(|&i| rb.position[i][3] > 0.0)
        .map(|i| dvec(&rb.indirect[i]))
        .collect();
    seen.iter().sum::<DVec3>() / seen.len() as f64
}

/// The names of the passes of a run's last frame.
fn passes(r: &Rendered) -> Vec<&'static str> {
    r.stats
        .frames
        .last()
        .unwrap()
        .iter()
        .map(|p| p.name)
        .collect()
}

/// Inside a closed sphere bounce k adds `rho^k Phi / A` everywhere
/// (docs/algorithm.md section 5.9): what `--bounces 2` adds to `--bounces 1`
/// is bounce 2, what 3 adds to 2 is bounce 3, and `inf` adds the rest of
/// the series. Three albedos at once, one per channel, with the grid's
/// visibility, which must block no chord inside the convex sphere.
#[test]
fn inside_a_closed_sphere_each_bounce_adds_rho_to_the_k() {
    let gpu = gpu();
    let rho = DVec3::new(0.8, 0.5, 0.2);
    let (scene, area) = sphere(rho.as_vec3(), 3);
    let phi_over_a = spot_power() / area;
    let base = sized("rsm-gather", 48, 48, 64).with(&VISIBILITY, Visibility::Voxels);
    let means: Vec<DVec3> = [1, 2, 3]
        .map(Bounces::Count)
        .into_iter()
        .chain([Bounces::Infinite])
        .map(|n| mean_indirect(&render(&gpu, &scene, &with_bounces(&base, n), 1)))
        .collect();
    let first = phi_over_a * series(rho, Some(1));
    println!("bounce 1: {:.5} (exact {first:.5})", means[0]);
    for (k, n) in [(1, Some(2)), (2, Some(3))] {
        let added = means[k] - means[k - 1];
        let exact = phi_over_a * (series(rho, n) - series(rho, Some(k as u32)));
        let off = (added - exact) / exact;
        println!("bounces {k} -> {n:?}: adds {added:.5}, exact {exact:.5}: off by {off:+.3}");
        assert!(
            off.abs().cmple(DVec3::splat(PER_BOUNCE * k as f64)).all(),
            "{n:?}: off by {off}"
        );
    }
    let every = phi_over_a * series(rho, None);
    let off = (means[3] - every) / every;
    println!(
        "every bounce: {:.5}, exact {every:.5}: off by {off:+.3}",
        means[3]
    );
    assert!(
        off.abs().cmple(DVec3::splat(EVERY)).all(),
        "inf: off by {off}"
    );
}

/// What the cells lose per bounce: a face does not light itself (inside
/// the sphere its own share of the surface is under 1/150 with 8^3 cells),
/// and the disc kernel falls short of the sphere's 1 / A between
/// neighbours; measured 1.8% at bounce 2 and 3.2% at bounce 3 (the loss
/// compounds): 3% a bounce allows bounce k to be (k - 1) times 3% short,
/// a 65% margin over the measured rate.
const PER_BOUNCE: f64 = 0.03;

/// Every bounce at once: the per-bounce loss above compounds through the
/// series (at rho 0.8, 0.984 rho sums to 7.5% less than rho), and the 1%
/// test stops it with a tail of about 4% left; measured 8.5% short in red,
/// 1.9% in green, 0.8% in blue. 12% allows the loss per bounce to grow by
/// a third.
const EVERY: f64 = 0.12;

/// `--bounces 1` makes no bounce pass, so its frame is the commands (and
/// the image) of the one-bounce renderer; two bounces add the passes.
#[test]
fn one_bounce_makes_no_bounce_pass() {
    let gpu = gpu();
    let scene = cornell_at_rest(true);
    let base = sized("rsm-gather", 32, 32, 32).with(&VISIBILITY, Visibility::Voxels);
    let one = render(&gpu, &scene, &with_bounces(&base, Bounces::ONE), 1);
    assert!(!passes(&one).iter().any(|p| p.starts_with("bounce-")));
    let two = render(&gpu, &scene, &with_bounces(&base, Bounces::Count(2)), 1);
    for p in ["bounce-cells", "bounce-gather", "bounce-add"] {
        assert!(passes(&two).contains(&p), "{p}: {:?}", passes(&two));
    }
}

/// In the box with its blocks, N bounces are nearer the path-traced truth
/// of N bounces than one bounce is, for N = 2 and every bounce.
#[test]
fn in_the_box_n_bounces_are_nearer_the_truth_of_n_bounces() {
    let gpu = gpu();
    let scene = cornell_at_rest(true);
    let base = sized("rsm-gather", 48, 48, 64).with(&VISIBILITY, Visibility::Voxels);
    let one = render(&gpu, &scene, &base, 1);
    let shadows = ShadowMaps::new(&one.light_views, one.origin, 64, base.pcf_radius);
    for n in [Bounces::Count(2), Bounces::Infinite] {
        let truth = trace(&scene, &one.readback, &shadows, 0.05, 1, n, |_, _| {});
        let many = render(&gpu, &scene, &with_bounces(&base, n), 1);
        let (e1, en) = (
            truth.model_error(&one.readback.indirect),
            truth.model_error(&many.readback.indirect),
        );
        println!(
            "{}: 1 bounce is {e1:.4} from the truth, {n:?} bounces {en:.4} (truth noise {:.4})",
            n.words(),
            truth.noise
        );
        assert!(en < e1, "{n:?}: {en} against one bounce's {e1}");
    }
}

/// Every method that renders bounces runs the bounce passes with
/// `--bounces 2` and `inf` (every pass) without a validation message.
#[test]
fn every_method_that_renders_bounces_is_validation_clean() {
    let gpu = validating_gpu();
    let scene = cornell_at_rest(true);
    for d in isr::methods::REGISTRY
        .iter()
        .filter(|d| d.renders_bounces())
    {
        let s = small_params(sized(d.key().name(), 32, 32, 32), 64, 4, 1 << 20)
            .with(&VISIBILITY, Visibility::Voxels);
        for n in [Bounces::Count(2), Bounces::Infinite] {
            let r = render(&gpu, &scene, &with_bounces(&s, n), 2);
            assert!(passes(&r).contains(&"bounce-add"), "{}", d.key().name());
        }
    }
}

/// A grey floor in black walls: the path tracer's bounces 2 and on are
/// exactly 0 (tests/bounces.rs), as the floor sees only the walls. The
/// walls are faces of their own in every cell (docs/algorithm.md section
/// 5.9), with albedo 0, so they re-emit nothing; what bounces 2 and 3 add
/// comes from the finest cells where floor and wall meet, whose surface
/// mixes the two albedos and both facings. Measured: see BLACK_WALLS.
#[test]
fn black_walls_add_little_beyond_the_first_bounce() {
    let gpu = gpu();
    let scene = common::black_walls::floor_in_black_walls();
    let base = sized("rsm-gather", 48, 48, 64).with(&VISIBILITY, Visibility::Voxels);
    let one = mean_indirect(&render(&gpu, &scene, &base, 1));
    let three = mean_indirect(&render(
        &gpu,
        &scene,
        &with_bounces(&base, Bounces::Count(3)),
        1,
    ));
    let added = (three - one) / one;
    println!("bounces 2 and 3 add {added:.4} of the first bounce");
    assert!(one.x > 0.0 && added.max_element() < BLACK_WALLS, "{added}");
}

/// What bounces 2 and 3 may add over a black-walled floor, as a share of
/// the first bounce: measured 0.0018 (one albedo and one normal per cell,
/// before the cells had faces, gave 0.031).
const BLACK_WALLS: f64 = 0.01;
