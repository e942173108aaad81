//! glTF animation through the loader: sampling in a node hierarchy against
//! matrices worked out by hand, the camera and the light following their
//! nodes, still scenes, export round trips, and one test per kind of bad
//! animation data (the message names the animation and the channel).

use glam::{Mat4, Quat, Vec3, Vec4};
use isr::scene::animation::{Animation, Channel, Interpolation, Local, Parent, Property, Trs};
use isr::scene::{cornell::cornell_box, gltf_load, Scene};
use serde_json::{json, Value};
use std::f32::consts::FRAC_PI_4;

/// Buffer, views and accessors of a test document, embedded as base64.
#[derive(Default)]
struct Bin {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    fn accessor(&mut self, bytes: &[u8], count: usize, ty: &str, component: u32) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.accessors
            .push(json!({"bufferView": self.views.len() - 1,
            "componentType": component, "count": count, "type": ty}));
        self.accessors.len() - 1
    }

    fn floats(&mut self, v: &[f32], ty: &str) -> usize {
        let width = match ty {
            "SCALAR" => 1,
            "VEC3" => 3,
            _ => 4,
        };
        let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.accessor(&bytes, v.len() / width, ty, 5126)
    }

    /// A sampler with keyframe `times` and flat `values` (VEC3, or VEC4 for rotations).
    fn sampler(&mut self, interpolation: &str, times: &[f32], values: &[f32], ty: &str) -> Value {
        let input = self.floats(times, "SCALAR");
        if times.iter().all(|t| t.is_finite()) {
            self.accessors[input]["min"] = json!([times[0]]);
            self.accessors[input]["max"] = json!([times[times.len() - 1]]);
        }
        let output = self.floats(values, ty);
        json!({"input": input, "output": output, "interpolation": interpolation})
    }
}

/// A document with one triangle mesh, one perspective camera, one spot light,
/// `nodes` (roots are the nodes nobody lists as a child) and the animations
/// `animations` builds.
fn doc(nodes: Value, animations: impl FnOnce(&mut Bin) -> Value) -> Value {
    let mut b = Bin::default();
    let pos = b.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], "VEC3");
    b.accessors[pos]["min"] = json!([0., 0., 0.]);
    b.accessors[pos]["max"] = json!([1., 1., 0.]);
    let animations = animations(&mut b);
    let n = nodes.as_array().unwrap();
    let children: Vec<&Value> = n
        .iter()
        .filter_map(|x| x.get("children"))
        .flat_map(|c| c.as_array().unwrap())
        .collect();
    let roots: Vec<usize> = (0..n.len())
        .filter(|i| !children.contains(&&json!(i)))
        .collect();
    use base64::Engine as _;
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "intensity": 5.0,
            "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}]}},
        "scene": 0,
        "scenes": [{"nodes": roots}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.05}}],
        "animations": animations,
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": b.bin.len(), "uri": format!("data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&b.bin))}],
    })
}

fn try_load(doc: &Value, name: &str) -> anyhow::Result<Scene> {
    let dir = std::env::temp_dir().join(format!("isr-anim-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("scene.gltf");
    std::fs::write(&p, serde_json::to_string(doc).unwrap()).unwrap();
    gltf_load::load(&p)
}

fn load(doc: &Value, name: &str) -> Scene {
    try_load(doc, name).unwrap()
}

/// The error message of a file that must not load.
fn error(doc: &Value, name: &str) -> String {
    match try_load(doc, name) {
        Ok(_) => panic!("{name}: the file loaded"),
        Err(e) => format!("{e:#}"),
    }
}

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
    doc(nodes, |b| {
        let quarter = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let spin = b.sampler(
            "LINEAR",
            &[0.0, 1.0],
            &[0., 0., 0., 1., quarter.x, quarter.y, quarter.z, quarter.w],
            "VEC4",
        );
        let slide = b.sampler("LINEAR", &[0.0, 2.0], &[1., 0., 0., 1., 0., 2.], "VEC3");
        json!([{"name": "spin and slide", "samplers": [spin, slide], "channels": [
            {"sampler": 0, "target": {"node": 1, "path": "rotation"}},
            {"sampler": 1, "target": {"node": 2, "path": "translation"}},
        ]}])
    })
}

/// Index of the instance whose rest transform puts the mesh's origin at `x`.
fn instance_at(s: &Scene, x: f32) -> usize {
    s.instances
        .iter()
        .position(|i| (i.world_from_object.w_axis.x - x).abs() < 1e-6)
        .unwrap()
}

#[test]
fn nested_animated_nodes_compose_parent_then_child() {
    let s = load(&nested_doc(), "nested");
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
    // The camera 1 m along the slider's +Z (scaled by 2).
    let mut eye = mesh;
    eye.w_axis += Vec4::new(2.0 * sn, 0.0, 2.0 * c, 0.0);
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
    let d = doc(nodes, |b| {
        // Keys at 0 and 2 s: values (0,0,5) and (4,0,5), out-tangent of the
        // first (0,1,0), in-tangent of the second (0,0,-1).
        let dolly = b.sampler(
            "CUBICSPLINE",
            &[0.0, 2.0],
            &[
                0., 0., 0., 0., 0., 5., 0., 1., 0., 0., 0., -1., 4., 0., 5., 0., 0., 0.,
            ],
            "VEC3",
        );
        let down = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
        let tilt = Quat::from_rotation_z(FRAC_PI_4) * down;
        let turn = b.sampler(
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
    let s = load(&d, "follow");
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
    let mut d =
        serde_json::from_str::<Value>(&isr::scene::export::to_gltf_json(&cornell_box()).unwrap())
            .unwrap();
    d.as_object_mut().unwrap().remove("animations");
    let s = load(&d, "still");
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
    let d: Value = serde_json::from_str(&isr::scene::export::to_gltf_json(&s).unwrap()).unwrap();
    let file = load(&d, "roundtrip");
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
    let mut d = doc(nodes, |b| {
        let w = b.floats(&[0.0, 1.0], "SCALAR");
        let t = b.floats(&[0.0, 1.0], "SCALAR");
        json!([{"samplers": [{"input": t, "output": w}],
            "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}])
    });
    d["skins"] = json!([{"joints": [1]}]);
    let s = load(&d, "skin");
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

// Bad animation data. Channel 0 of animation "broken" is fine; channel 1 is
// broken in one way per test.

fn broken(channel1: impl FnOnce(&mut Bin) -> (Value, Value)) -> Value {
    let nodes = json!([{"mesh": 0}, {"mesh": 0, "translation": [2.0, 0.0, 0.0]}]);
    doc(nodes, |b| {
        let good = b.sampler("LINEAR", &[0.0, 1.0], &[0., 0., 0., 1., 0., 0.], "VEC3");
        let (sampler, target) = channel1(b);
        json!([{"name": "broken", "samplers": [good, sampler], "channels": [
            {"sampler": 0, "target": {"node": 0, "path": "translation"}},
            {"sampler": 1, "target": target},
        ]}])
    })
}

fn to_node_1() -> Value {
    json!({"node": 1, "path": "translation"})
}

const LABEL: &str = r#"animation 0 ("broken") channel 1"#;

fn assert_names(e: &str, cause: &str) {
    assert!(
        e.contains(LABEL),
        "the message does not name the channel: {e}"
    );
    assert!(e.contains(cause), "the message does not say {cause:?}: {e}");
}

#[test]
fn input_and_output_counts_disagree() {
    let d = broken(|b| {
        let s = b.sampler(
            "LINEAR",
            &[0.0, 1.0, 2.0],
            &[0., 0., 0., 1., 0., 0.],
            "VEC3",
        );
        (s, to_node_1())
    });
    assert_names(
        &error(&d, "counts"),
        "the input has 3 keyframe times but the output has 2 values",
    );
}

#[test]
fn times_that_do_not_increase() {
    let d = broken(|b| {
        let s = b.sampler("STEP", &[0.0, 1.0, 1.0], &[0.; 9], "VEC3");
        (s, to_node_1())
    });
    assert_names(
        &error(&d, "increase"),
        "keyframe times must increase strictly",
    );
    let d = broken(|b| {
        let s = b.sampler("STEP", &[1.0, 0.5], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    assert_names(
        &error(&d, "decrease"),
        "time 1 (0.5 s) is not after time 0 (1 s)",
    );
}

#[test]
fn nan_keys_and_values() {
    let d = broken(|b| {
        let s = b.sampler("LINEAR", &[0.0, f32::NAN], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    assert_names(&error(&d, "nan-time"), "keyframe time 1 is NaN");
    let d = broken(|b| {
        let s = b.sampler(
            "LINEAR",
            &[0.0, 1.0],
            &[0., 0., 0., 0., f32::INFINITY, 0.],
            "VEC3",
        );
        (s, to_node_1())
    });
    assert_names(&error(&d, "inf-value"), "output value 1 is not finite");
}

#[test]
fn target_node_that_does_not_exist() {
    let d = broken(|b| {
        let s = b.sampler("LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, json!({"node": 9, "path": "translation"}))
    });
    assert_names(
        &error(&d, "node"),
        "targets node 9, which does not exist (the file has 2 nodes)",
    );
}

#[test]
fn sampler_that_does_not_exist() {
    let mut d = broken(|b| {
        let s = b.sampler("LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    d["animations"][0]["channels"][1]["sampler"] = json!(5);
    assert_names(
        &error(&d, "sampler"),
        "uses sampler 5, which does not exist (the animation has 2 samplers)",
    );
}

#[test]
fn cubic_spline_output_not_three_per_time() {
    let d = broken(|b| {
        let s = b.sampler("CUBICSPLINE", &[0.0, 1.0], &[0.; 12], "VEC3");
        (s, to_node_1())
    });
    assert_names(
        &error(&d, "cubic"),
        "the CUBICSPLINE output has 4 values for 2 keyframe times",
    );
}

#[test]
fn non_float_accessors() {
    // Times as unsigned shorts.
    let d = broken(|b| {
        let input = b.accessor(&[0, 0, 1, 0], 2, "SCALAR", 5123);
        let output = b.floats(&[0.; 6], "VEC3");
        (json!({"input": input, "output": output}), to_node_1())
    });
    let e = error(&d, "u16-times");
    assert_names(&e, "input accessor");
    assert_names(&e, "component type U16: animation keys must be floats");
    // Rotations as bytes that are not normalized.
    let d = broken(|b| {
        let input = b.floats(&[0.0], "SCALAR");
        let output = b.accessor(&[0, 0, 0, 127], 1, "VEC4", 5120);
        (
            json!({"input": input, "output": output}),
            json!({"node": 1, "path": "rotation"}),
        )
    });
    assert_names(&error(&d, "i8-rotation"), "component type I8");
}

#[test]
fn normalized_integer_rotations_are_read() {
    // glTF allows normalized integer rotations: (0, 0, 0, 127) / 127 is the
    // identity, (0, 127, 0, 0) / 127 half a turn about +Y.
    let d = broken(|b| {
        let input = b.floats(&[0.0, 1.0], "SCALAR");
        let output = b.accessor(&[0, 0, 0, 127, 0, 127, 0, 0], 2, "VEC4", 5120);
        b.accessors[output]["normalized"] = json!(true);
        (
            json!({"input": input, "output": output, "interpolation": "STEP"}),
            json!({"node": 1, "path": "rotation"}),
        )
    });
    let s = load(&d, "i8-normalized");
    let i = instance_at(&s, 2.0);
    let turned = s.state_at(1.0).instance_transforms[i];
    assert!(turned.abs_diff_eq(
        Mat4::from_translation(Vec3::X * 2.0) * Mat4::from_rotation_y(std::f32::consts::PI),
        1e-6
    ));
}

#[test]
fn key_data_outside_its_buffer_view() {
    let mut d = broken(|b| {
        let s = b.sampler("LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    // The output accessor (the last one) claims a third key its view lacks.
    let last = d["accessors"].as_array().unwrap().len() - 1;
    d["accessors"][last]["count"] = json!(3);
    assert_names(&error(&d, "short-view"), "lies outside buffer view");
}

#[test]
fn animated_node_with_a_matrix() {
    let mut d = broken(|b| {
        let s = b.sampler("LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    d["nodes"][1] = json!({"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 2,0,0,1]});
    assert_names(&error(&d, "matrix"), "which has a matrix");
}

#[test]
fn unnamed_animations_are_named_by_index() {
    let mut d = broken(|b| {
        let s = b.sampler("LINEAR", &[0.0, 1.0, 2.0], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    d["animations"][0].as_object_mut().unwrap().remove("name");
    let e = error(&d, "unnamed");
    assert!(e.contains("animation 0 channel 1:"), "{e}");
}

#[test]
fn target_path_or_accessor_that_does_not_exist() {
    let mut d = broken(|b| {
        let s = b.sampler("LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, json!({"node": 1, "path": "colour"}))
    });
    assert_names(
        &error(&d, "path"),
        "the target path is not translation, rotation, scale or weights",
    );
    d["animations"][0]["channels"][1]["target"]["path"] = json!("translation");
    d["animations"][0]["samplers"][1]["output"] = json!(40);
    assert_names(
        &error(&d, "accessor"),
        "the output accessor 40 of sampler 1 does not exist",
    );
}
