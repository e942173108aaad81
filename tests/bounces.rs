//! The path tracer's bounces (docs/algorithm.md section 5.4, "Bounces"): the
//! light of bounces 1, 2, 3 and 4 on, traced once in layers of their own,
//! against the closed sphere's exact answer; their sums over N bounces
//! against each other; and a black surface that ends every path.
mod common;

use common::black_walls::floor_in_black_walls;
use common::sphere::{series, sphere, spot_power};
use common::*;
use glam::DVec3;
use isr::bounces::{Bounces, LAYERS};
use isr::pathtrace::{render as trace, PathTraceSettings};
use isr::readback::Readback;
use isr::scene::Scene;

fn pt(scene: &Scene, size: u32, spp: u32, seed: u64, bounces: Bounces) -> Readback {
    trace(
        scene,
        &PathTraceSettings {
            width: size,
            height: size,
            spp,
            seed,
            exposure: 1.0,
            bounces,
        },
        |_, _| {},
    )
}

/// The image of `n` bounces read from a trace's layers: the first `n` summed.
fn sum_of_layers(r: &Readback, n: Bounces) -> Vec<DVec3> {
    (0..r.indirect.len())
        .map(|i| r.bounces[..n.layers()].iter().map(|l| dvec(&l[i])).sum())
        .collect()
}

/// Mean and standard error of the mean of `values`, per channel.
fn mean_and_error(values: &[DVec3]) -> (DVec3, DVec3) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<DVec3>() / n;
    let var = values
        .iter()
        .map(|v| (*v - mean) * (*v - mean))
        .sum::<DVec3>()
        / (n - 1.0);
    (mean, (var / n).powf(0.5))
}

/// The subdivision of the test's sphere (20,480 facets), and what its
/// facets do to the answer. On the sphere the first bounce's irradiance is
/// uniform because every patch sees every other with form factor `A_j / A`;
/// on a polyhedron a facet sees neither itself nor its neighbours as the
/// sphere would. The area-weighted mean over the whole surface stays exactly
/// `rho^k Phi / A` per bounce (every ray leaving a closed surface lands on
/// it); only how the light spreads over the facets changes, toward the lit
/// cap. Measured in this view at 1,024 spp (noise 0.13-0.2%), the first
/// bounce off the formula on the lit cap and the unlit wall: +1.4% and
/// -0.5% at level 2, +0.24% and -0.24% at level 3, +0.12% and -0.14% at
/// level 4, +0.10% and -0.12% at level 5: falling as the facets' area (4x a
/// level) until the noise hides it, so under 0.1% at level 5; every bounce
/// together, less. The margin allows 0.2%.
const LEVEL: u32 = 5;
const TESSELLATION: f64 = 0.002;

/// Inside a closed sphere of albedo `rho` the indirect irradiance of N
/// bounces is uniform and exact (docs/algorithm.md section 5.4, "Bounces"):
/// `(Phi / A) rho (1 - rho^N) / (1 - rho)`, whatever the spot lights.
/// Three albedos at once (one per channel; Russian roulette reads the
/// largest), N = 1, 2, 3 and inf from one trace, on the lit cap and off it.
#[test]
fn inside_a_closed_sphere_n_bounces_give_the_geometric_series() {
    let rho = DVec3::new(0.8, 0.5, 0.2);
    let (scene, area) = sphere(rho.as_vec3(), LEVEL);
    let traced = pt(&scene, 64, 128, 1, Bounces::Infinite);
    assert_eq!(traced.bounces.len(), LAYERS.len());
    let lit: Vec<bool> = traced.direct.iter().map(|d| d[0] > 0.0).collect();
    let n_lit = lit.iter().filter(|&&l| l).count();
    assert!(
        n_lit > 600 && lit.len() - n_lit > 600,
        "{n_lit} of {} pixels lit",
        lit.len()
    );
    let phi_over_a = spot_power() / area;
    for n in [
        Bounces::ONE,
        Bounces::Count(2),
        Bounces::Count(3),
        Bounces::Infinite,
    ] {
        let expected = phi_over_a * series(rho, n.last());
        let sums = sum_of_layers(&traced, n);
        for (group, on_cap) in [("lit cap", true), ("unlit wall", false)] {
            let values: Vec<DVec3> = (0..sums.len())
                .filter(|&i| lit[i] == on_cap)
                .map(|i| sums[i])
                .collect();
            let (mean, error) = mean_and_error(&values);
            let off = (mean - expected) / expected;
            let noise = error / expected;
            println!(
                "{n:?} {group} ({} px): E = {mean:.5}, expected {expected:.5}: off by \
                 {off:+.4} (relative), standard error {noise:.4}",
                values.len()
            );
            // Four standard errors of the estimator's noise, plus the
            // facets' effect on how the light spreads (`TESSELLATION`).
            let margin = 4.0 * noise + DVec3::splat(TESSELLATION);
            assert!(
                off.abs().cmple(margin).all(),
                "{n:?} {group}: off by {off}, allowed {margin}"
            );
        }
    }
}

/// The mean over the pixels with geometry of `values`, with its standard
/// error, per channel.
fn over_geometry(r: &Readback, values: &[DVec3]) -> (DVec3, DVec3) {
    let seen: Vec<DVec3> = (0..values.len())
        .filter(|&i| r.position[i][3] > 0.0)
        .map(|i| values[i])
        .collect();
    mean_and_error(&seen)
}

/// In the built-in box (with its blocks) the light summed over N bounces
/// grows with N pixel by pixel (every layer is light, none negative), each
/// bounce bringing less than the one before, and converges: an image of N
/// bounces traced alone (other seeds) is the sum of the first N layers of
/// one trace of every bounce, for N = 1, 2, 3, and 8 bounces fall short of
/// every bounce by no more than the light beyond the eighth.
#[test]
fn the_sum_over_n_bounces_grows_with_n_and_converges() {
    let scene = cornell_at_rest(true);
    let (size, spp) = (32, 256);
    let every = pt(&scene, size, spp, 1, Bounces::Infinite);
    let sums: Vec<Vec<DVec3>> = [1, 2, 3]
        .map(Bounces::Count)
        .into_iter()
        .chain([Bounces::Infinite])
        .map(|n| sum_of_layers(&every, n))
        .collect();
    for i in 0..every.indirect.len() {
        for w in sums.windows(2) {
            assert!(
                w[0][i].cmple(w[1][i]).all(),
                "pixel {i}: {} then {}",
                w[0][i],
                w[1][i]
            );
        }
        assert!(
            (sums[3][i] - dvec(&every.indirect[i])).abs().max_element()
                <= 1e-5 * sums[3][i].max_element()
        );
    }
    let layer = |k: usize| -> DVec3 {
        let values: Vec<DVec3> = every.bounces[k].iter().map(dvec).collect();
        over_geometry(&every, &values).0
    };
    let means: Vec<DVec3> = (0..LAYERS.len()).map(layer).collect();
    println!("mean light of bounces 1, 2, 3, 4 on: {means:?}");
    // The box's whitest albedo is 0.75, and its open front lets light out:
    // each bounce brings less than 0.75 of the one before (measured: 0.41
    // to 0.53 by channel, the noise under 1%).
    for k in 0..2 {
        assert!(
            means[k + 1].cmplt(0.75 * means[k]).all(),
            "bounce {} brings {} after {}",
            k + 2,
            means[k + 1],
            means[k]
        );
    }
    for (k, n) in [1, 2, 3, 8].into_iter().enumerate() {
        let alone = pt(&scene, size, spp, 2 + k as u64, Bounces::Count(n));
        // Read from the trace of every bounce: its first N layers, or for
        // N = 8 all of them, less the light beyond the eighth bounce: r^5
        // of the light beyond the third, r the bounce ratio (0.41 to 0.55
        // measured here: under 5%); 15% allows r to 0.68. Pixel by pixel,
        // so that the noise of the mean difference is the estimators' (the
        // image's own variation cancels).
        let short: Vec<DVec3> = (0..alone.indirect.len())
            .map(|i| sums[k.min(3)][i] - dvec(&alone.indirect[i]))
            .collect();
        let (short, noise) = over_geometry(&alone, &short);
        let tail = match n {
            8 => 0.15 * means[3],
            _ => DVec3::ZERO,
        };
        println!(
            "{n} bounces alone: the layers of every bounce's trace are {short:.5} more \
             (noise {noise:.5}, tail allowed {tail:.5})"
        );
        assert!(
            short.cmpge(-4.0 * noise).all() && short.cmple(4.0 * noise + tail).all(),
            "{n} bounces: the layers are {short} more (noise {noise}, tail {tail})"
        );
    }
}

/// A grey floor in a box of black walls (albedo 0, open above), the spot on
/// the floor: the floor's light reaches the walls (the first bounce), and
/// nothing reflects it on, since the floor sees only the walls. Bounces 2
/// and later add exactly nothing: a black surface ends every path.
#[test]
fn black_walls_add_nothing_beyond_the_first_bounce() {
    let s = floor_in_black_walls();
    let traced = pt(&s, 32, 32, 1, Bounces::Infinite);
    let mut lit_walls = 0;
    for i in 0..traced.indirect.len() {
        let first = dvec(&traced.bounces[0][i]);
        for (k, layer) in traced.bounces.iter().enumerate().skip(1) {
            assert_eq!(layer[i][..3], [0.0; 3], "pixel {i}: bounce layer {}", k + 1);
        }
        assert_eq!(dvec(&traced.indirect[i]), first, "pixel {i}");
        lit_walls += (first.max_element() > 0.0) as usize;
    }
    println!("{lit_walls} pixels lit by the first bounce");
    assert!(
        lit_walls > 100,
        "{lit_walls} pixels lit by the first bounce"
    );
}

/// `--bounces` on the command line: the path tracer writes a layer per
/// bounce into its EXR, summing to `indirect`; a count out of range, or not
/// a count, is refused naming the option; a GPU method is warned that it
/// does not read it.
#[test]
fn the_command_line_takes_bounces_for_the_path_tracer_and_warns_the_gpu_methods() {
    use common::cli::Isr;
    let dir = common::temp_dir("bounces-cli");
    let ran = Isr::tiny(&dir)
        .args(["--method", "pathtrace", "--spp", "4", "--bounces", "inf"])
        .succeeds();
    assert!(!ran.stderr.contains("warning"), "{}", ran.stderr);
    assert!(ran.stderr.contains("every bounce"), "{}", ran.stderr);
    let image = exr::prelude::read_all_flat_layers_from_file(dir.join("out/render.exr")).unwrap();
    let layer = |name: &str| -> Vec<f32> {
        let l = image
            .layer_data
            .iter()
            .find(|l| {
                l.attributes
                    .layer_name
                    .as_ref()
                    .map(|n| n.to_string())
                    .as_deref()
                    == Some(name)
            })
            .unwrap_or_else(|| panic!("no layer {name}"));
        match &l.channel_data.list[0].sample_data {
            exr::prelude::FlatSamples::F32(v) => v.clone(),
            other => panic!("{name}: {other:?}"),
        }
    };
    let indirect = layer("indirect");
    let sum = LAYERS
        .iter()
        .map(|n| layer(n))
        .fold(vec![0.0; indirect.len()], |s, l| {
            s.iter().zip(l).map(|(a, b)| a + b).collect()
        });
    for (a, b) in indirect.iter().zip(&sum) {
        assert!((a - b).abs() <= 1e-6 * a.abs().max(1e-3), "{a} against {b}");
    }
    assert!(layer(LAYERS[3]).iter().any(|&v| v > 0.0));
    let e = Isr::tiny(&dir)
        .args(["--method", "pathtrace", "--bounces", "9"])
        .fails();
    assert!(e.contains("--bounces 9: must be within [1, 8]"), "{e}");
    let e = Isr::tiny(&dir)
        .args(["--method", "pathtrace", "--bounces", "many"])
        .fails();
    assert!(e.contains("'many' is neither"), "{e}");
    let ran = Isr::tiny(&dir)
        .args(["--method", "none", "--bounces", "2"])
        .succeeds();
    assert!(
        ran.stderr.contains("method none does not read --bounces"),
        "{}",
        ran.stderr
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
