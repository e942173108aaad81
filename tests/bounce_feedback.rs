//! Temporal feedback of the bounced light (`--bounce-feedback on`,
//! docs/algorithm.md section 5.9): off, nothing is carried between frames
//! with every bounce; on, a still scene's frames sum the series one bounce
//! a frame, the first frame being two bounces, and settle on `--bounces
//! inf`; validation-clean with several light views.
mod common;

use common::*;
use isr::bounce::FEEDBACK;
use isr::bounces::{Bounces, BOUNCES};
use isr::readback::Readback;
use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::RenderSettings;
use isr::visibility::{Visibility, VISIBILITY};

fn base(bounces: Bounces, feedback: bool) -> RenderSettings {
    sized("rsm-gather", 32, 32, 32)
        .with(&VISIBILITY, Visibility::Voxels)
        .with(&BOUNCES, bounces)
        .with(&FEEDBACK, feedback)
}

/// The relative RMSE of `a`'s indirect image against `b`'s over the pixels
/// with geometry (docs/algorithm.md section 6.1).
fn rel_rmse(a: &Readback, b: &Readback) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for i in (0..a.indirect.len()).filter(|&i| b.position[i][3] > 0.0) {
        let (x, y) = (dvec(&a.indirect[i]), dvec(&b.indirect[i]));
        num += (x - y).length_squared();
        den += y.length_squared();
    }
    (num / den).sqrt()
}

/// Without feedback (the default) every bounce is computed within the frame:
/// a frame after others equals its time rendered alone, bit for bit. With
/// it the same frame differs: the light it kept from the other poses.
#[test]
fn without_feedback_a_frame_with_every_bounce_equals_its_time_rendered_alone() {
    let gpu = validating_gpu();
    let scene = cornell_box();
    let sequence = |s: &RenderSettings| {
        let mut r = Renderer::new(&gpu, &scene, s).unwrap();
        for t in [0.0, 0.5, 1.0] {
            r.update(&scene.state_at(t)).unwrap();
            r.render_frames(2, |_| {}).unwrap();
        }
        r.readback().unwrap()
    };
    let plain = base(Bounces::Infinite, false);
    let in_sequence = sequence(&plain);
    let mut alone = Renderer::new(&gpu, &scene, &plain).unwrap();
    alone.update(&scene.state_at(1.0)).unwrap();
    alone.render_frames(1, |_| {}).unwrap();
    let alone = alone.readback().unwrap();
    assert_eq!(in_sequence.indirect, alone.indirect);
    assert_eq!(in_sequence.final_radiance, alone.final_radiance);
    let fed = sequence(&base(Bounces::Infinite, true));
    assert_validation_clean(&gpu);
    assert_ne!(fed.indirect, alone.indirect, "feedback kept nothing");
}

/// With feedback a still scene's first frame has the power of one
/// propagation from nothing: two bounces. Frame k sums bounces 2 to k + 1
/// at the receivers, so after 40 frames (the box keeps well under 0.8 of
/// its bounced power a bounce: 0.8^40 < 1e-3 of it left) the image is
/// `--bounces inf`'s, but for the tail that `inf` leaves when a bounce adds
/// under 1% of the sum (section 5.9): at most 1% / (1 - 0.8) = 5% of the
/// bounced light, itself under half the indirect light in the box, so 2.5%
/// of the indirect image; the bound is 3%.
#[test]
fn with_feedback_a_still_scene_settles_on_every_bounce() {
    let gpu = validating_gpu();
    let scene = cornell_at_rest(true);
    let two = render(&gpu, &scene, &base(Bounces::Count(2), false), 1).readback;
    let every = render(&gpu, &scene, &base(Bounces::Infinite, false), 1).readback;
    let fed = base(Bounces::Infinite, true);
    let first = render(&gpu, &scene, &fed, 1);
    assert!(
        first
            .stats
            .frames
            .last()
            .unwrap()
            .iter()
            .any(|p| p.name == "bounce-feedback"),
        "no bounce-feedback pass"
    );
    let e_first = rel_rmse(&first.readback, &two);
    // The same sums in the same order but for adding 0: a rounding at most.
    assert!(e_first < 1e-5, "first frame {e_first} from two bounces");
    let settled = render(&gpu, &scene, &fed, 40).readback;
    let e_settled = rel_rmse(&settled, &every);
    let e_two = rel_rmse(&two, &every);
    println!("feedback: first frame {e_first:.2e} from 2 bounces; 40 frames {e_settled:.4} from inf (2 bounces: {e_two:.4})");
    assert!(e_settled < 0.03, "40 frames {e_settled} from inf");
    assert!(
        e_settled < e_two / 3.0,
        "{e_settled} against 2 bounces' {e_two}"
    );
}

/// A point light renders six views, each with its own kept power: with
/// feedback they do not mix (validation clean, and a still scene settles).
#[test]
fn with_feedback_each_light_view_keeps_its_own_power() {
    let gpu = validating_gpu();
    let mut scene = isr::scene::load_file(
        std::path::Path::new("assets/cornell-point.gltf"),
        &Default::default(),
    )
    .unwrap();
    scene.animation = None;
    let every = render(&gpu, &scene, &base(Bounces::Infinite, false), 1).readback;
    let settled = render(&gpu, &scene, &base(Bounces::Infinite, true), 40).readback;
    let e = rel_rmse(&settled, &every);
    println!("point light, 40 frames with feedback: {e:.4} from inf");
    // As above: the tail `inf` leaves, the point's bounced share alike.
    assert!(e < 0.03, "{e}");
}
