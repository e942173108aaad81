//! Bad animation data, one test per kind: the message names the animation
//! and the channel. Channel 0 of animation "broken" is fine; channel 1 is
//! broken in one way per test. Also: normalized integer rotations, which are
//! valid, are read.
mod common;

use common::gltf::{animated_doc, load_error_in, load_in, sampler, Doc};
use common::instance_at;
use glam::{Mat4, Vec3};
use serde_json::{json, Value};

fn broken(channel1: impl FnOnce(&mut Doc) -> (Value, Value)) -> Value {
    let nodes = json!([{"mesh": 0}, {"mesh": 0, "translation": [2.0, 0.0, 0.0]}]);
    animated_doc(nodes, |d| {
        let good = sampler(d, "LINEAR", &[0.0, 1.0], &[0., 0., 0., 1., 0., 0.], "VEC3");
        let (channel, target) = channel1(d);
        json!([{"name": "broken", "samplers": [good, channel], "channels": [
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
    let d = broken(|d| {
        let s = sampler(
            d,
            "LINEAR",
            &[0.0, 1.0, 2.0],
            &[0., 0., 0., 1., 0., 0.],
            "VEC3",
        );
        (s, to_node_1())
    });
    assert_names(
        &load_error_in("anim-counts", &d),
        "the input has 3 keyframe times but the output has 2 values",
    );
}

#[test]
fn times_that_do_not_increase() {
    let d = broken(|d| {
        let s = sampler(d, "STEP", &[0.0, 1.0, 1.0], &[0.; 9], "VEC3");
        (s, to_node_1())
    });
    assert_names(
        &load_error_in("anim-increase", &d),
        "keyframe times must increase strictly",
    );
    let d = broken(|d| {
        let s = sampler(d, "STEP", &[1.0, 0.5], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    assert_names(
        &load_error_in("anim-decrease", &d),
        "time 1 (0.5 s) is not after time 0 (1 s)",
    );
}

#[test]
fn nan_keys_and_values() {
    let d = broken(|d| {
        let s = sampler(d, "LINEAR", &[0.0, f32::NAN], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    assert_names(
        &load_error_in("anim-nan-time", &d),
        "keyframe time 1 is NaN",
    );
    let d = broken(|d| {
        let s = sampler(
            d,
            "LINEAR",
            &[0.0, 1.0],
            &[0., 0., 0., 0., f32::INFINITY, 0.],
            "VEC3",
        );
        (s, to_node_1())
    });
    assert_names(
        &load_error_in("anim-inf-value", &d),
        "output value 1 is not finite",
    );
}

#[test]
fn target_node_that_does_not_exist() {
    let d = broken(|d| {
        let s = sampler(d, "LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, json!({"node": 9, "path": "translation"}))
    });
    assert_names(
        &load_error_in("anim-node", &d),
        "targets node 9, which does not exist (the file has 2 nodes)",
    );
}

#[test]
fn sampler_that_does_not_exist() {
    let mut d = broken(|d| {
        let s = sampler(d, "LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    d["animations"][0]["channels"][1]["sampler"] = json!(5);
    assert_names(
        &load_error_in("anim-sampler", &d),
        "uses sampler 5, which does not exist (the animation has 2 samplers)",
    );
}

#[test]
fn cubic_spline_output_not_three_per_time() {
    let d = broken(|d| {
        let s = sampler(d, "CUBICSPLINE", &[0.0, 1.0], &[0.; 12], "VEC3");
        (s, to_node_1())
    });
    assert_names(
        &load_error_in("anim-cubic", &d),
        "the CUBICSPLINE output has 4 values for 2 keyframe times",
    );
}

#[test]
fn non_float_accessors() {
    // Times as unsigned shorts.
    let d = broken(|d| {
        let input = d.data(&[0, 0, 1, 0], 2, "SCALAR", 5123);
        let output = d.floats(&[0.; 6], "VEC3");
        (json!({"input": input, "output": output}), to_node_1())
    });
    let e = load_error_in("anim-u16-times", &d);
    assert_names(&e, "input accessor");
    assert_names(&e, "component type U16: animation keys must be floats");
    // Rotations as bytes that are not normalized.
    let d = broken(|d| {
        let input = d.floats(&[0.0], "SCALAR");
        let output = d.data(&[0, 0, 0, 127], 1, "VEC4", 5120);
        (
            json!({"input": input, "output": output}),
            json!({"node": 1, "path": "rotation"}),
        )
    });
    assert_names(&load_error_in("anim-i8-rotation", &d), "component type I8");
}

#[test]
fn normalized_integer_rotations_are_read() {
    // glTF allows normalized integer rotations: (0, 0, 0, 127) / 127 is the
    // identity, (0, 127, 0, 0) / 127 half a turn about +Y.
    let d = broken(|d| {
        let input = d.floats(&[0.0, 1.0], "SCALAR");
        let output = d.data(&[0, 0, 0, 127, 0, 127, 0, 0], 2, "VEC4", 5120);
        d.json["accessors"][output]["normalized"] = json!(true);
        (
            json!({"input": input, "output": output, "interpolation": "STEP"}),
            json!({"node": 1, "path": "rotation"}),
        )
    });
    let s = load_in("anim-i8-normalized", &d).unwrap();
    let i = instance_at(&s, 2.0);
    let turned = s.state_at(1.0).instance_transforms[i];
    assert!(turned.abs_diff_eq(
        Mat4::from_translation(Vec3::X * 2.0) * Mat4::from_rotation_y(std::f32::consts::PI),
        1e-6
    ));
}

#[test]
fn key_data_outside_its_buffer_view() {
    let mut d = broken(|d| {
        let s = sampler(d, "LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    // The output accessor (the last one) claims a third key its view lacks.
    let last = d["accessors"].as_array().unwrap().len() - 1;
    d["accessors"][last]["count"] = json!(3);
    assert_names(
        &load_error_in("anim-short-view", &d),
        "lies outside buffer view",
    );
}

#[test]
fn animated_node_with_a_matrix() {
    let mut d = broken(|d| {
        let s = sampler(d, "LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    d["nodes"][1] = json!({"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 2,0,0,1]});
    assert_names(&load_error_in("anim-matrix", &d), "which has a matrix");
}

#[test]
fn unnamed_animations_are_named_by_index() {
    let mut d = broken(|d| {
        let s = sampler(d, "LINEAR", &[0.0, 1.0, 2.0], &[0.; 6], "VEC3");
        (s, to_node_1())
    });
    d["animations"][0].as_object_mut().unwrap().remove("name");
    let e = load_error_in("anim-unnamed", &d);
    assert!(e.contains("animation 0 channel 1:"), "{e}");
}

#[test]
fn target_path_or_accessor_that_does_not_exist() {
    let mut d = broken(|d| {
        let s = sampler(d, "LINEAR", &[0.0, 1.0], &[0.; 6], "VEC3");
        (s, json!({"node": 1, "path": "colour"}))
    });
    assert_names(
        &load_error_in("anim-path", &d),
        "the target path is not translation, rotation, scale or weights",
    );
    d["animations"][0]["channels"][1]["target"]["path"] = json!("translation");
    d["animations"][0]["samplers"][1]["output"] = json!(40);
    assert_names(
        &load_error_in("anim-accessor", &d),
        "the output accessor 40 of sampler 1 does not exist",
    );
}
