//! Frames change with the frame state: the renderer re-renders the scene
//! posed at each time, with nothing of the indirect light kept between frames.
mod common;

use common::cli::Isr;
use common::*;
use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::RenderSettings;

fn settings() -> RenderSettings {
    sized("hisr", 64, 64, 64)
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

/// Where the short block of the box goes in `moving_block_scene` at t = 1 s:
/// next to the white back wall (z = -1), 8 cm from it.
const BLOCK_MOVE: glam::Vec3 = glam::Vec3::new(0.1, 0.0, -0.85);

/// The Cornell box with its light still and its short block blue; with
/// `animated`, a LINEAR translation moves the block by `BLOCK_MOVE` between
/// 0 s and 1 s, without it the block stands where `placed` puts it.
fn moving_block_scene(animated: bool, placed: glam::Vec3) -> isr::scene::Scene {
    use isr::scene::animation::{Animation, Channel, Interpolation, Local, Parent, Property, Trs};
    let mut s = cornell_box();
    s.animation = None;
    let blue = s.add_material("blue", glam::Vec3::new(0.05, 0.15, 0.8));
    let block = s
        .instances
        .iter()
        .position(|i| s.meshes[i.mesh].name == "short-block")
        .unwrap();
    let mesh = s.instances[block].mesh;
    s.meshes[mesh].material = blue;
    let rest = s.instances[block].world_from_object;
    if animated {
        let mut a = Animation::default();
        let node = a
            .add_node(
                Parent::Fixed(glam::Mat4::IDENTITY),
                Local::Animated(Trs {
                    translation: glam::Vec3::ZERO,
                    rotation: glam::Quat::IDENTITY,
                    scale: glam::Vec3::ONE,
                }),
            )
            .unwrap();
        let child = a.add_node(Parent::Node(node), Local::Fixed(rest)).unwrap();
        a.add_channel(
            Channel::new(
                node,
                Property::Translation,
                Interpolation::Linear,
                vec![0.0, 1.0],
                vec![glam::Vec4::ZERO, BLOCK_MOVE.extend(0.0)],
            )
            .unwrap(),
        )
        .unwrap();
        a.attach_instance(block, child);
        s.animation = Some(a);
    } else {
        s.instances[block].world_from_object = glam::Mat4::from_translation(placed) * rest;
    }
    s
}

/// Blue over red of the indirect light summed over the back wall's pixels
/// with `x` in `xs` (the wall is white, so only the bounce colours it).
fn back_wall_blue(r: &isr::readback::Readback, xs: std::ops::Range<f32>) -> f64 {
    let (mut red, mut blue) = (0.0f64, 0.0f64);
    for ((p, n), l) in r.position.iter().zip(&r.normal).zip(&r.indirect) {
        if p[3] > 0.0 && n[2] > 0.99 && p[2] < -0.99 && xs.contains(&p[0]) && p[1] < 1.0 {
            red += l[0] as f64;
            blue += l[2] as f64;
        }
    }
    assert!(red > 0.0, "no lit back-wall pixels with x in {xs:?}");
    blue / red
}

/// A coloured block moved by a glTF-style animation: in the frame where it has
/// moved, its shadow and its bounce are where it now is. The frame equals a
/// still scene with the block placed there, and the white wall it now stands
/// beside turns blue near it.
#[test]
fn a_moving_block_casts_its_shadow_and_bounce_where_it_now_is() {
    let gpu = gpu();
    let settings = RenderSettings {
        width: 96,
        height: 96,
        rsm_resolution: 128,
        ..settings()
    };
    let animated = moving_block_scene(true, glam::Vec3::ZERO);
    assert_eq!(animated.animation_duration(), Some(1.0));
    let mut r = Renderer::new(&gpu, &animated, &settings).unwrap();
    r.update(&animated.state_at(0.0)).unwrap();
    r.render_frames(1, |_| {}).unwrap();
    let before = r.readback().unwrap();
    r.update(&animated.state_at(1.0)).unwrap();
    r.render_frames(1, |_| {}).unwrap();
    let after = r.readback().unwrap();
    drop(r);
    let still = render(&gpu, &moving_block_scene(false, BLOCK_MOVE), &settings, 1).readback;
    let at_rest = render(
        &gpu,
        &moving_block_scene(false, glam::Vec3::ZERO),
        &settings,
        1,
    )
    .readback;
    assert_validation_clean(&gpu);

    // Frame 0 is the block at rest, frame 1 the block moved, float for float
    // (both place the block through the same instance transform).
    let close = |a: &[[f32; 4]], b: &[[f32; 4]], what: &str| {
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            for c in 0..3 {
                assert!(
                    (x[c] - y[c]).abs() <= 1e-5 * y[c].abs().max(1e-3),
                    "{what} pixel {i} channel {c}: {} animated, {} still",
                    x[c],
                    y[c]
                );
            }
        }
    };
    close(
        &before.final_radiance,
        &at_rest.final_radiance,
        "t = 0 final",
    );
    close(&after.indirect, &still.indirect, "t = 1 indirect");
    close(&after.direct, &still.direct, "t = 1 direct");
    close(&after.final_radiance, &still.final_radiance, "t = 1 final");

    // The shadow moved: direct light changed on the floor.
    let floor_changed = before
        .direct
        .iter()
        .zip(&after.direct)
        .zip(&after.normal)
        .filter(|((a, b), n)| n[1] > 0.99 && (a[0] - b[0]).abs() > 0.1 * a[0].max(b[0]))
        .count();
    assert!(
        floor_changed > 50,
        "the shadow moved over only {floor_changed} floor pixels"
    );

    // The bounce moved: beside the block's new place the wall's indirect light
    // turned bluer; the far side of the wall changed much less.
    let near = BLOCK_MOVE.x + 0.05..BLOCK_MOVE.x + 0.6;
    let far = -0.95..-0.5;
    let (near_before, near_after) = (
        back_wall_blue(&before, near.clone()),
        back_wall_blue(&after, near),
    );
    let (far_before, far_after) = (
        back_wall_blue(&before, far.clone()),
        back_wall_blue(&after, far),
    );
    eprintln!(
        "blue/red near {near_before:.3} -> {near_after:.3}, far {far_before:.3} -> {far_after:.3}"
    );
    assert!(
        near_after > 1.5 * near_before,
        "the wall beside the block's new place: blue/red {near_before:.3} -> {near_after:.3}"
    );
    assert!(
        near_after / near_before > 2.0 * (far_after / far_before),
        "the bounce should grow most beside the block: near x{:.2}, far x{:.2}",
        near_after / near_before,
        far_after / far_before
    );
}

/// A camera moved by an orbit changes the image, and equals a still scene
/// whose camera stands where the orbit put it.
#[test]
fn a_moving_camera_changes_the_image() {
    use isr::scene::motion::{orbit_camera, pivot};
    let gpu = gpu();
    let mut scene = cornell_box();
    scene.animation = None;
    let rest = render(&gpu, &scene, &settings(), 1).readback;
    let mut state = scene.rest_state();
    orbit_camera(&mut state, pivot(&scene), 8.0, 0.5);
    let mut r = Renderer::new(&gpu, &scene, &settings()).unwrap();
    r.update(&state).unwrap();
    r.render_frames(1, |_| {}).unwrap();
    let moved = r.readback().unwrap();
    drop(r);
    let mut placed = scene.clone();
    placed.camera = state.camera;
    let still = render(&gpu, &placed, &settings(), 1).readback;
    assert_validation_clean(&gpu);
    assert_eq!(moved.final_radiance, still.final_radiance);
    let changed = rest
        .final_radiance
        .iter()
        .zip(&moved.final_radiance)
        .filter(|(a, b)| (a[0] - b[0]).abs() > 0.05 * a[0].max(b[0]).max(1e-3))
        .count();
    assert!(
        changed > 64 * 64 / 4,
        "the camera's orbit changed only {changed} pixels"
    );
}

/// `isr render --sequence`: the files, every frame's time in timings.json,
/// the GIF, and a frame equal to its time rendered alone by `--time`.
#[test]
fn the_sequence_command_writes_frames_timings_and_a_gif() {
    let dir = temp_dir("sequence");
    let run = |extra: &[&str]| {
        Isr::render(&dir)
            .args([
                "--method", "hisr", "--width", "48", "--height", "32", "--rsm", "64",
            ])
            .arg("--validate")
            .args(extra)
            .succeeds()
    };
    let seq = dir.join("seq");
    run(&[
        "--time",
        "0.25",
        "--frames",
        "3",
        "--fps",
        "2",
        "--gif",
        "--sequence",
        "seq",
    ]);
    let alone = dir.join("alone.png");
    run(&[
        "--time",
        "1.25",
        "--frames",
        "1",
        "--png",
        "alone.png",
        "--out",
        "alone.exr",
    ]);
    for k in 0..3 {
        assert!(seq.join(format!("frame_{k:04}.exr")).is_file());
    }
    let timings: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(seq.join("timings.json")).unwrap()).unwrap();
    let times: Vec<f64> = timings["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["time"].as_f64().unwrap())
        .collect();
    assert_eq!(times, [0.25, 0.75, 1.25]);
    let png = |p: &std::path::Path| image::open(p).unwrap().to_rgb8();
    let (last, alone) = (png(&seq.join("frame_0002.png")), png(&alone));
    assert_eq!(last.dimensions(), (48, 32));
    assert!(
        last == alone,
        "frame 2 (t = 1.25 s) differs from --time 1.25"
    );
    assert!(
        png(&seq.join("frame_0000.png")) != last,
        "the sweep moved nothing"
    );
    let gif = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(seq.join("sequence.gif")).unwrap(),
    ))
    .unwrap();
    use image::AnimationDecoder;
    let frames = gif.into_frames().collect_frames().unwrap();
    assert_eq!(frames.len(), 3);
    assert_eq!(frames[0].delay().numer_denom_ms(), (500, 1));
}
