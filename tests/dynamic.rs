//! Frames change with the frame state: the renderer re-renders the scene
//! posed at each time, with nothing of the indirect light kept between frames.
mod common;

use common::*;
use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::{Method, RenderSettings};

fn settings() -> RenderSettings {
    RenderSettings {
        width: 64,
        height: 64,
        rsm_resolution: 64,
        vpls: 64,
        method: Method::Hisr,
        ..Default::default()
    }
}

/// A frame rendered after others equals the same time rendered alone, and
/// the light's sweep changes the image.
#[test]
fn a_sequence_frame_equals_its_time_rendered_alone() {
    let gpu = gpu();
    let scene = cornell_box();
    assert!(
        scene.animation_duration().is_some(),
        "the built-in box sweeps its light"
    );
    let mut r = Renderer::new(&gpu, &scene, &settings()).unwrap();
    let mut first = None;
    for t in [0.0, 0.5, 1.0] {
        r.update(&scene.state_at(t)).unwrap();
        r.render_frames(2, |_| {}).unwrap();
        first.get_or_insert_with(|| r.readback().unwrap());
    }
    let in_sequence = r.readback().unwrap();
    drop(r);
    let mut alone = Renderer::new(&gpu, &scene, &settings()).unwrap();
    alone.update(&scene.state_at(1.0)).unwrap();
    alone.render_frames(1, |_| {}).unwrap();
    let alone = alone.readback().unwrap();
    assert_validation_clean(&gpu);
    assert_eq!(in_sequence.final_radiance, alone.final_radiance);
    assert_eq!(in_sequence.indirect, alone.indirect);
    let first = first.unwrap();
    let moved = first
        .indirect
        .iter()
        .zip(&alone.indirect)
        .filter(|(a, b)| (a[0] - b[0]).abs() > 1e-3 * b[0].abs().max(1e-3))
        .count();
    assert!(
        moved > 64 * 64 / 4,
        "the sweep changed only {moved} indirect pixels"
    );
}

/// A frame state with the wrong number of instance transforms is refused.
#[test]
fn a_frame_state_must_place_every_instance() {
    let gpu = gpu();
    let scene = cornell_box();
    let mut r = Renderer::new(&gpu, &scene, &settings()).unwrap();
    let mut state = scene.rest_state();
    state.instance_transforms.pop();
    let e = r.update(&state).unwrap_err();
    assert!(e.to_string().contains("instance transforms"), "{e}");
}
