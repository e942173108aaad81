//! What HISR's `--tau` means (docs/algorithm.md section 4.3): with the
//! relative tau (the default) the same tau gives about the same error
//! against the dense gather on scenes lit very differently; the talk's
//! absolute tau does not. The table of errors per bench scene and tau is a
//! measurement, not a check: `cargo run --release --example hisr_tau`.
mod common;

use common::*;
use glam::Vec3;
use isr::methods::hisr;
use isr::passes::rsm_tree::{PatchKernel, PATCH_KERNEL};
use isr::regular_vpls::VPLS;
use isr::renderer::Renderer;
use isr::scene::{cornell::cornell_box, Scene};
use isr::settings::{Method, RenderSettings};

/// One frame: the indirect image, the pixels with geometry and the light
/// patches per eye-space patch.
struct Measured {
    indirect: Vec<[f32; 4]>,
    mask: Vec<bool>,
    per_patch: f64,
}

fn measure(gpu: &isr::vk::Gpu, scene: &Scene, s: &RenderSettings) -> Measured {
    let mut r = Renderer::new(gpu, scene, s).expect("renderer setup");
    r.render_frames(1, |_| {}).expect("rendering");
    let out = r.readback().expect("readback");
    let m = r.readback_multires().expect("readback").expect("multires");
    drop(r);
    assert_validation_clean(gpu);
    Measured {
        mask: geometry_mask(&out.position),
        indirect: out.indirect,
        per_patch: isr::debug_view::light_patch_stats(&m, None).per_patch_mean,
    }
}

/// HISR's error against the dense gather through the same eye-space patches
/// (every RSM texel a VPL), at `tau` in `mode`, down to single texels, and
/// its light patches per eye-space patch. 64x64, RSM 64.
///
/// Patches are evaluated at their centres (`--patch-kernel centre`), so
/// that the error is the split test's: the second-order kernel takes most of
/// a valid patch's error away, which leaves the invalid patches' (tested in
/// [`the_second_order_kernel_makes_whole_patches_err_less`]).
fn hisr_error(gpu: &isr::vk::Gpu, scene: &Scene, tau: f32, mode: hisr::TauMode) -> (f64, f64) {
    hisr_error_with(gpu, scene, tau, mode, PatchKernel::Centre)
}

/// [`hisr_error`] with the patch kernel `kernel`.
fn hisr_error_with(
    gpu: &isr::vk::Gpu,
    scene: &Scene,
    tau: f32,
    mode: hisr::TauMode,
    kernel: PatchKernel,
) -> (f64, f64) {
    let (size, rsm) = (64, 64);
    let at = |method| {
        RenderSettings {
            method: Method::new(method),
            ..sized("none", size, size, rsm)
        }
        .with(&PATCH_KERNEL, kernel)
    };
    let dense = measure(gpu, scene, &at("multires-gather").with(&VPLS, rsm * rsm));
    let s = at("hisr")
        .with(&hisr::TAU, tau)
        .with(&hisr::TAU_MODE, mode)
        .with(&hisr::MAX_DEPTH, rsm.ilog2());
    let h = measure(gpu, scene, &s);
    assert!(dense.mask.iter().any(|&g| g));
    let peak = dense
        .indirect
        .iter()
        .map(|p| p[0].max(p[1]).max(p[2]))
        .fold(0.0, f32::max);
    assert!(peak > 0.0, "no indirect light");
    (
        relative_rmse(&h.indirect, &dense.indirect, &dense.mask),
        h.per_patch,
    )
}

/// The built-in box lit two ways: its wide spot (60 degrees) under the
/// ceiling, and a narrow one (20 degrees) in a corner aimed at the floor,
/// which lights a small patch of it. The talk's absolute tau compares a
/// patch's bound with a nominal texel solid angle, so the narrow cone, whose
/// texels are far smaller than nominal, is refined far more at the same tau;
/// the relative tau uses each patch's own area.
fn two_lightings() -> [(&'static str, Scene); 2] {
    let wide = cornell_box();
    let mut narrow = cornell_box();
    narrow.animation = None;
    narrow.lights = vec![spot(
        Vec3::new(-0.8, 1.8, 0.6),
        Vec3::new(0.3, 0.0, -0.2),
        3.0,
        15.0,
        20.0,
    )];
    [("wide spot", wide), ("narrow spot", narrow)]
}

/// At one tau (0.02), the relative tau's errors on the two lightings are
/// within 2x of each other, and each is below tau; the absolute tau's are
/// more than 2x apart (the finding, kept as the contrast).
#[test]
fn relative_tau_gives_like_errors_on_differently_lit_scenes() {
    let gpu = gpu();
    let tau = 0.02;
    let mut spread = vec![];
    for mode in [hisr::TauMode::Relative, hisr::TauMode::Absolute] {
        let errors: Vec<(f64, f64)> = two_lightings()
            .iter()
            .map(|(_, scene)| hisr_error(&gpu, scene, tau, mode))
            .collect();
        println!("{mode:?}, tau {tau}: (error, light patches per eye patch): {errors:?}");
        let (lo, hi) = errors
            .iter()
            .fold((f64::MAX, 0.0f64), |(lo, hi), e| (lo.min(e.0), hi.max(e.0)));
        assert!(lo > 0.0, "{mode:?}: {errors:?}");
        if mode == hisr::TauMode::Relative {
            assert!(
                hi < tau as f64,
                "{mode:?}: errors {errors:?} above tau {tau}"
            );
        }
        spread.push(hi / lo);
    }
    println!(
        "spread (largest error over smallest): relative {:.2}, absolute {:.2}",
        spread[0], spread[1]
    );
    assert!(spread[0] <= 2.0, "relative tau: spread {:.2}", spread[0]);
    assert!(spread[1] > 2.0, "absolute tau: spread {:.2}", spread[1]);
}

/// The relative tau bounds the error for every light type: at tau 0.02 the
/// box's spot, point light (six cube faces) and directional light each give
/// an error below tau (the guarantee), and each error is the one measured,
/// 0.491%, 0.605% and 0.345%, within 10% (a regression value; the spread
/// between light types, 1.75x, is printed, not held).
#[test]
fn relative_tau_bounds_the_error_for_every_light_type() {
    let gpu = gpu();
    let tau = 0.02;
    let scenes = [
        ("spot", cornell_box()),
        ("point", cornell_with(vec![box_point()])),
        ("directional", cornell_with(vec![box_sun()])),
    ];
    let errors: Vec<(&str, f64)> = scenes
        .iter()
        .map(|(name, scene)| {
            (
                *name,
                hisr_error(&gpu, scene, tau, hisr::TauMode::Relative).0,
            )
        })
        .collect();
    println!("relative tau {tau}: {errors:?}");
    let lo = errors.iter().map(|e| e.1).fold(f64::MAX, f64::min);
    let hi = errors.iter().map(|e| e.1).fold(0.0, f64::max);
    println!("spread (largest error over smallest): {:.2}", hi / lo);
    assert!(hi < tau as f64, "{errors:?} above tau {tau}");
    // Margin 10%: the errors were the same to every digit in three runs
    // and with LP_NUM_THREADS=0; moving tau itself by 2%, which flips far
    // more refinement decisions than another driver's rounding could,
    // moves them by 1.2% to 2.5%.
    let measured = [0.004908, 0.006051, 0.003455];
    for ((name, e), m) in errors.iter().zip(measured) {
        assert!(
            (e / m - 1.0).abs() < 0.1,
            "{name}: error {e:.6} where {m} was measured"
        );
    }
}

/// The second-order patch kernel (docs/algorithm.md section 2.6): HISR's
/// whole patches err less against the dense gather than evaluated at their
/// centres, at the same tau and so the same light patches, on both
/// lightings of the box; single texels (the dense gather itself) are the
/// same under both kernels, bit for bit.
#[test]
fn the_second_order_kernel_makes_whole_patches_err_less() {
    let gpu = gpu();
    let tau = 0.1;
    for (name, scene) in two_lightings() {
        let (centre, n_centre) = hisr_error_with(
            &gpu,
            &scene,
            tau,
            hisr::TauMode::Relative,
            PatchKernel::Centre,
        );
        let (second, n_second) = hisr_error_with(
            &gpu,
            &scene,
            tau,
            hisr::TauMode::Relative,
            PatchKernel::SecondOrder,
        );
        println!("{name}: centre {centre:.5} ({n_centre:.0} per patch), second-order {second:.5} ({n_second:.0})");
        assert_eq!(
            n_centre, n_second,
            "{name}: the kernel changed the traversal"
        );
        assert!(
            second < 0.75 * centre,
            "{name}: second-order {second} against centre {centre}"
        );
    }
    let dense = |kernel| {
        let s = RenderSettings {
            method: Method::new("multires-gather"),
            ..sized("none", 64, 64, 64)
        }
        .with(&VPLS, 64 * 64)
        .with(&PATCH_KERNEL, kernel);
        measure(&gpu, &cornell_box(), &s).indirect
    };
    assert!(
        dense(PatchKernel::Centre) == dense(PatchKernel::SecondOrder),
        "single texels differ between the kernels"
    );
}
