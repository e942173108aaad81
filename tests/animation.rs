//! glTF animation through the loader: sampling in a node hierarchy against
//! matrices worked out by hand, the camera and the light following their
//! nodes, still scenes, export round trips, skins and morph weights ignored
//! (bad animation data: `animation_errors.rs`).
mod common;

use common::gltf::{animated_doc, exported, load_in, sampler};
use common::instance_at;
use glam::{Mat4, Quat, Vec3, Vec4};
use isr::scene::animation::{Animation, Channel, Interpolation, Local, Parent, Property, Trs};
use isr::scene::{cornell::cornell_box, Scene};
use serde_json::{json, Value};
use std::f32::consts::FRAC_PI_4;

const S45: f32 = std::f32::consts::FRAC_1_SQRT_2;

/// base (static, lifted 2 m) > spinner (rotates about +Y, 0 to 90 degrees
/// in 1 s) > slider (scale 2, moves from (1,0,0) to (1,0,2) in 2 s, carries the
/// mesh) > eye (static offset, carries the camera); the light hangs 1 m from
/// the spinner's origin; node 5 is a static mesh.
fn nested_doc() -> Value {
    let nodes = json!([
        {"name": "base", "translation": [0.0, 2.0, 0.0], "children": [1]},
        {"name": "spinner", "children": [2, 4]},
        {"name": "slider", "mesh": 0, "translation": [1.0, 0.0, 0.0], "scale": [2.0, 2.0, 2.0], "children": [3]},
        {"name": "eye", "camera": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1]},
        {"name": "lamp", "translation": [0.0, 0.0, 1.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "still", "mesh": 0, "translation": [5.0, 0.0, 0.0]},
    ]);
    animated_doc(nodes, |d| {
        let quarter = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let spin = sampler(
            d,
            "LINEAR",
            &[0.0, 1.0],
            &[0., 0., 0., 1., quarter.x, quarter.y, quarter.z, quarter.w],
            "VEC4",
        );
        let slide = sampler(d, "LINEAR", &[0.0, 2.0], &[1., 0., 0., 1., 0., 2.], "VEC3");
        json!([{"name": "spin and slide", "samplers": [spin, slide], "channels": [
            {"sampler": 0, "target": {"node": 1, "path": "rotation"}},
            {"sampler": 1, "target": {"node": 2, "path": "translation"}},
        ]}])
    })
}

#[test]
fn nested_animated_nodes_compose_parent_then_child() {
    let s = load_in("anim-nested", &nested_doc()).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.animation_duration(), Some(2.0));
    let (moving, still) = (instance_at(&s, 1.0), instance_at(&s, 5.0));
    let st = s.state_at(0.5);
    // base * spinner * slider at 0.5 s: R = 45 degrees about +Y (c = s = 1/sqrt 2),
    // slider T(1, 0, 0.5) S(2): [2R | (0,2,0) + R (1,0,0.5)].
    let (c, sn) = (S45, S45);
    #[rustfmt::skip]
    let mesh = Mat4::from_cols_array(&[
        2.0 * c, 0.0, -2.0 * sn, 0.0,
        0.0, 2.0, 0.0, 0.0,
        2.0 * sn, 0.0, 2.0 * c, 0.0,
        c + 0.5 * sn, 2.0, -sn + 0.5 * c, 1.0,
    ]);
    assert!(
        st.instance_transforms[moving].abs_diff_eq(mesh, 1e-6),
        "{:?}",
        st.instance_transforms[moving]
    );
    assert_eq!(
        st.instance_transforms[still],
        s.instances[still].world_from_object
    );
    // The camera 1 m along the slider's +Z (scaled by 2), turned as the
    // slider, without its scale (a camera's view is its own).
    let eye = Mat4::from_cols(
        mesh.x_axis / 2.0,
        mesh.y_axis / 2.0,
        mesh.z_axis / 2.0,
        mesh.w_axis + Vec4::new(2.0 * sn, 0.0, 2.0 * c, 0.0),
    );
    assert!(st.camera.world_from_camera.abs_diff_eq(eye, 1e-6));
    // The light 1 m along the spinner's +Z, pointing along its -Z.
    assert!(st.lights[0]
        .position
        .abs_diff_eq(Vec3::new(sn, 2.0, c), 1e-6));
    assert!(st.lights[0]
        .direction
        .abs_diff_eq(Vec3::new(-sn, 0.0, -c), 1e-6));

    // Clamped: before the first keys the first values, after the last the last.
    let before = s.state_at(-3.0);
    assert!(before.instance_transforms[moving].abs_diff_eq(
        Mat4::from_translation(Vec3::new(1.0, 2.0, 0.0)) * Mat4::from_scale(Vec3::splat(2.0)),
        1e-6
    ));
    let after = s.state_at(10.0);
    let want = Mat4::from_translation(Vec3::Y * 2.0)
        * Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2)
        * Mat4::from_translation(Vec3::new(1.0, 0.0, 2.0))
        * Mat4::from_scale(Vec3::splat(2.0));
    assert!(after.instance_transforms[moving].abs_diff_eq(want, 1e-6));
    assert_eq!(after, s.state_at(2.0));
}

#[test]
fn camera_and_light_follow_their_own_animated_nodes() {
    // The camera's node moves along a CUBICSPLINE; the light's node turns in
    // STEPs.
    let nodes = json!([
        {"mesh": 0},
        {"camera": 0, "translation": [0.0, 0.0, 5.0]},
        {"translation": [0.0, 3.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
    ]);
    let d = animated_doc(nodes, |d| {
        // Keys at 0 and 2 s: values (0,0,5) and (4,0,5), out-tangent of the
        // first (0,1,0), in-tangent of the second (0,0,-1).
        let dolly = sampler(
            d,
            "CUBICSPLINE",
            &[0.0, 2.0],
            &[
                0., 0., 0., 0., 0., 5., 0., 1., 0., 0., 0., -1., 4., 0., 5., 0., 0., 0.,
            ],
            "VEC3",
        );
        let down = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
        let tilt = Quat::from_rotation_z(FRAC_PI_4) * down;
        let turn = sampler(
            d,
            "STEP",
            &[0.0, 1.0],
            &[
                down.x, down.y, down.z, down.w, tilt.x, tilt.y, tilt.z, tilt.w,
            ],
            "VEC4",
        );
        json!([
            {"samplers": [dolly], "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]},
            {"samplers": [turn], "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}]},
        ])
    });
    let s = load_in("anim-follow", &d).unwrap();
    assert_eq!(s.animation_duration(), Some(2.0));
    // At 1 s: s = 0.5, dt = 2: 0.5 (0,0,5) + 0.125*2 (0,1,0) + 0.5 (4,0,5) - 0.125*2 (0,0,-1).
    let st = s.state_at(1.0);
    assert!(st
        .camera
        .world_from_camera
        .abs_diff_eq(Mat4::from_translation(Vec3::new(2.0, 0.25, 5.25)), 1e-6));
    // The light: straight down until 1 s, then tilted 45 degrees toward +x.
    let l = s.state_at(0.99).lights[0];
    assert!(l.position.abs_diff_eq(Vec3::new(0.0, 3.0, 0.0), 1e-6));
    assert!(l.direction.abs_diff_eq(-Vec3::Y, 1e-6));
    let l = st.lights[0];
    assert!(l.direction.abs_diff_eq(Vec3::new(S45, -S45, 0.0), 1e-6));
    assert_eq!(l.intensity, 5.0);
}

#[test]
fn still_scenes_stay_at_rest() {
    let mut d = exported(&cornell_box());
    d.as_object_mut().unwrap().remove("animations");
    let s = load_in("anim-still", &d).unwrap();
    assert!(s.animation.is_none());
    assert_eq!(s.animation_duration(), None);
    for t in [-1.0, 0.0, 2.5, 1e6] {
        assert_eq!(s.state_at(t), s.rest_state());
    }
    // Scenes built by code have no animation either.
    let mut built = cornell_box();
    built.animation = None;
    assert_eq!(built.state_at(1.0), built.rest_state());
}

#[test]
fn the_built_in_sweep_moves_the_light_only() {
    let s = cornell_box();
    assert_eq!(s.animation_duration(), Some(4.0));
    let rest = s.rest_state();
    let at0 = s.state_at(0.0);
    assert!(at0.lights[0]
        .position
        .abs_diff_eq(rest.lights[0].position, 1e-6));
    assert!(at0.lights[0]
        .direction
        .abs_diff_eq(rest.lights[0].direction, 1e-6));
    let mut xs = vec![];
    for k in 0..=16 {
        let st = s.state_at(k as f32 * 0.25);
        assert_eq!(st.instance_transforms, rest.instance_transforms);
        assert_eq!(st.camera, rest.camera);
        assert_eq!(st.lights[0].position, rest.lights[0].position);
        xs.push(st.lights[0].direction.x);
    }
    // Toward +x (green wall) at 1 s, back at 2 s, toward -x at 3 s, back at 4 s.
    let tilt = 40f32.to_radians().sin();
    assert!(xs[4] > 0.6 * tilt && xs[12] < -0.6 * tilt, "{xs:?}");
    assert!(xs[8].abs() < 1e-6 && xs[16].abs() < 1e-6);
    // The axis meets the green wall (x = 1) below the ceiling at 1 s.
    let l = s.state_at(1.0).lights[0];
    let y = l.position.y + l.direction.y * (1.0 - l.position.x) / l.direction.x;
    assert!((0.5..0.9).contains(&y), "meets the wall at y = {y}");
}

#[test]
fn export_round_trips_nested_animation() {
    // A hand-built scene: a static lift above an animated spinner carrying a
    // block, a static child node carrying the camera, the light on the spinner.
    let mut s = cornell_box();
    let mut a = Animation::default();
    let spinner = a
        .add_node(
            Parent::Fixed(Mat4::from_translation(Vec3::Y)),
            Local::Animated(Trs {
                translation: Vec3::new(0.2, 0.0, 0.0),
                rotation: Quat::IDENTITY,
                scale: Vec3::ONE,
            }),
        )
        .unwrap();
    let eye = a
        .add_node(
            Parent::Node(spinner),
            Local::Fixed(Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0))),
        )
        .unwrap();
    let keys = [0.0f32, 60.0, -30.0].map(|d| Vec4::from(Quat::from_rotation_y(d.to_radians())));
    a.add_channel(
        Channel::new(
            spinner,
            Property::Rotation,
            Interpolation::CubicSpline,
            vec![0.0, 0.5, 2.0],
            keys.iter()
                .flat_map(|&k| [Vec4::new(0.1, 0.0, 0.0, 0.0), k, Vec4::ZERO])
                .collect(),
        )
        .unwrap(),
    )
    .unwrap();
    a.add_channel(
        Channel::new(
            spinner,
            Property::Scale,
            Interpolation::Step,
            vec![0.0, 1.0],
            vec![Vec4::ONE, Vec4::new(1.0, 0.5, 1.0, 0.0)],
        )
        .unwrap(),
    )
    .unwrap();
    let short_block = s.instances.len() - 2;
    a.attach_instance(short_block, spinner);
    a.attach_camera(eye);
    a.attach_light(0, spinner);
    s.animation = Some(a);
    let d = exported(&s);
    let file = load_in("anim-roundtrip", &d).unwrap();
    assert!(file.warnings.is_empty(), "{:?}", file.warnings);
    assert_eq!(file.animation_duration(), Some(2.0));
    let mesh = |sc: &Scene, i: usize| sc.meshes[sc.instances[i].mesh].name.clone();
    for t in [-1.0, 0.0, 0.3, 0.5, 1.2, 2.0, 3.0] {
        let (a, b) = (file.state_at(t), s.state_at(t));
        assert!(
            a.camera
                .world_from_camera
                .abs_diff_eq(b.camera.world_from_camera, 1e-5),
            "t {t}"
        );
        assert!(
            a.lights[0].position.abs_diff_eq(b.lights[0].position, 1e-5),
            "t {t}"
        );
        assert!(
            a.lights[0]
                .direction
                .abs_diff_eq(b.lights[0].direction, 1e-5),
            "t {t}"
        );
        // Instances may come in another order from the file: match by mesh.
        for (i, m) in b.instance_transforms.iter().enumerate() {
            let j = (0..file.instances.len())
                .find(|&j| mesh(&file, j).starts_with(&mesh(&s, i)))
                .unwrap();
            assert!(
                a.instance_transforms[j].abs_diff_eq(*m, 1e-5),
                "t {t} instance {i}"
            );
        }
    }
    // The block really moves.
    let j = (0..file.instances.len())
        .find(|&j| mesh(&file, j).starts_with("short-block"))
        .unwrap();
    assert_ne!(
        file.state_at(0.5).instance_transforms[j],
        file.state_at(0.0).instance_transforms[j]
    );
}

#[test]
fn skins_and_morph_weights_are_ignored_with_warnings() {
    let nodes = json!([{"mesh": 0, "skin": 0}, {"name": "joint"}]);
    let mut d = animated_doc(nodes, |d| {
        let w = d.floats(&[0.0, 1.0], "SCALAR");
        let t = d.floats(&[0.0, 1.0], "SCALAR");
        json!([{"samplers": [{"input": t, "output": w}],
            "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}])
    });
    d["skins"] = json!([{"joints": [1]}]);
    let s = load_in("anim-skin", &d).unwrap();
    assert!(s.animation.is_none());
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("skin") && w.contains("ignored")),
        "{:?}",
        s.warnings
    );
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("animation 0 channel 0")
                && w.contains("morph target weights ignored")),
        "{:?}",
        s.warnings
    );
}
