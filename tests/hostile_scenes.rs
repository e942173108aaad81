//! Scene files that are broken or hostile in what they hold, run through the
//! release binary (issue 14 and the bad-input checks before it): malformed
//! JSON and GLB headers, views past their buffer, non-finite vertices,
//! attributes of the wrong type, bad lights and cameras, unsupported
//! extensions, a node DAG that expands to 2^40 instances, scenes too large
//! for the default light and camera, textures too large. Each is a clear
//! message and a non-zero exit, never a panic.
mod common;

use common::cli::Isr;
use common::gltf::*;
use common::temp_dir;
use serde_json::{json, Value};
use std::path::Path;

/// Renders `dir/scene.gltf` holding `doc`; expects a clean failure and
/// returns its message.
fn fails_on(dir: &Path, doc: &Value) -> String {
    write_scene(dir, doc);
    Isr::tiny(dir).args(["--scene", "scene.gltf"]).fails()
}

#[test]
fn malformed_json() {
    let dir = temp_dir("scene-json");
    std::fs::write(
        dir.join("bad.gltf"),
        "{ \"asset\": { \"version\": \"2.0\" }, ",
    )
    .unwrap();
    let e = Isr::tiny(&dir).args(["--scene", "bad.gltf"]).fails();
    assert!(e.contains("not a valid glTF 2.0 file"), "{e}");
}

#[test]
fn buffer_view_past_the_end_of_its_buffer() {
    let dir = temp_dir("scene-view");
    let mut doc = cornell_json();
    let len = doc["buffers"][0]["byteLength"].as_u64().unwrap();
    doc["bufferViews"][0]["byteOffset"] = json!(len - 4);
    let e = fails_on(&dir, &doc);
    assert!(e.contains("loading scene"), "{e}");
}

#[test]
fn non_finite_positions_and_normals_are_refused() {
    let dir = temp_dir("scene-nan");
    let mut scene = isr::scene::cornell::cornell_box();
    scene.meshes[2].vertices[1].position[1] = f32::NAN;
    let e = fails_on(&dir, &exported(&scene));
    assert!(e.contains("non-finite position"), "{e}");
    let mut scene = isr::scene::cornell::cornell_box();
    scene.meshes[1].vertices[2].normal = [f32::NAN, 0.0, 1.0];
    let e = fails_on(&dir, &exported(&scene));
    assert!(
        e.contains("mesh 1") && e.contains("vertex 2 has a non-finite normal"),
        "{e}"
    );
}

/// Texture coordinates are held to `Limits::texcoord`, as an OBJ's are:
/// (3e38, -3e38) is finite, and made every pixel NaN.
#[test]
fn texture_coordinates_past_their_limit_are_refused() {
    let dir = temp_dir("scene-uv");
    let mut tri = Doc::triangle();
    let uv = tri.floats(&[0., 0., 3e38, -3e38, 0., 1.], "VEC2");
    tri.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv);
    let e = fails_on(&dir, &tri.embedded());
    assert!(
        e.contains("vertex 1 has the TEXCOORD_0 [3e38, -3e38]") && e.contains("up to 65536"),
        "{e}"
    );
}

#[test]
fn attributes_of_the_wrong_type_are_refused() {
    let dir = temp_dir("scene-types");
    // POSITION accessor 0 of mesh 0, NORMAL 1, indices 2 (the exporter's order):
    // (accessor, patch, what must be, what it is).
    let cases = [
        (
            0,
            json!({"componentType": 5121}),
            "POSITION must be FLOAT VEC3",
            "UNSIGNED_BYTE VEC3",
        ),
        (
            0,
            json!({"type": "VEC2"}),
            "POSITION must be FLOAT VEC3",
            "FLOAT VEC2",
        ),
        (
            1,
            json!({"type": "VEC4"}),
            "NORMAL must be FLOAT VEC3",
            "FLOAT VEC4",
        ),
        (
            2,
            json!({"componentType": 5126}),
            "indices must be",
            "FLOAT SCALAR",
        ),
        (
            2,
            json!({"componentType": 5122}),
            "indices must be",
            "SHORT SCALAR",
        ),
    ];
    for (accessor, patch, expect, got) in cases {
        let mut doc = cornell_json();
        for (k, v) in patch.as_object().unwrap() {
            doc["accessors"][accessor][k] = v.clone();
        }
        let e = fails_on(&dir, &doc);
        assert!(
            e.contains("mesh 0 (floor) primitive 0") && e.contains(expect) && e.contains(got),
            "{e}"
        );
    }
}

/// Light 0 of the Cornell box replaced by, or patched with, each case; the
/// message names the light and what is wrong.
#[test]
fn bad_light_values_are_refused_with_what_is_wrong() {
    let dir = temp_dir("scene-light");
    let spot = |inner: f64, outer: f64| {
        json!({"type": "spot", "intensity": 5.0,
            "spot": {"innerConeAngle": inner, "outerConeAngle": outer}})
    };
    let replaced = [
        (json!({"type": "point", "intensity": -1.0}), "intensity -1"),
        (
            json!({"type": "directional", "intensity": -0.5}),
            "intensity -0.5",
        ),
        // 1e39 is beyond f32: it loads as infinity.
        (json!({"type": "point", "intensity": 1e39}), "intensity inf"),
        (
            json!({"type": "point", "intensity": 1.0, "color": [1.0, -0.2, 1.0]}),
            "color",
        ),
        (
            json!({"type": "directional", "intensity": 1.0, "color": [1e39, 1.0, 1.0]}),
            "color",
        ),
        (spot(0.5, 0.5), "outer cone above the inner"),
        (spot(0.6, 0.4), "outer cone above the inner"),
        (spot(0.2, 1.7), "at most 90 degrees"),
    ];
    for (light, what) in replaced {
        let mut doc = cornell_json();
        doc["extensions"]["KHR_lights_punctual"]["lights"][0] = light.clone();
        let e = fails_on(&dir, &doc);
        assert!(e.contains("light 0") && e.contains(what), "{light}: {e}");
    }
    let patched = [
        (json!({"color": [1.0, -0.5, 1.0]}), "color"),
        (json!({"intensity": -3.0}), "intensity"),
        (json!({"intensity": 1e38, "color": [10, 10, 10]}), "color"),
        (
            json!({"spot": {"innerConeAngle": 0.6, "outerConeAngle": 0.5}}),
            "cone angles",
        ),
        (
            json!({"spot": {"innerConeAngle": 0.2, "outerConeAngle": 1.7}}),
            "cone angles",
        ),
        (json!({"range": -1.0}), "range"),
    ];
    for (patch, what) in patched {
        let mut doc = cornell_json();
        let light = &mut doc["extensions"]["KHR_lights_punctual"]["lights"][0];
        for (k, v) in patch.as_object().unwrap() {
            light[k] = v.clone();
        }
        let e = fails_on(&dir, &doc);
        assert!(e.contains("light 0") && e.contains(what), "{patch}: {e}");
    }
    // A light node with scale 0.
    let mut doc = cornell_json();
    let l = doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .position(|n| n.get("extensions").is_some())
        .unwrap();
    doc["nodes"][l] =
        json!({"extensions": {"KHR_lights_punctual": {"light": 0}}, "scale": [0, 0, 0]});
    let e = fails_on(&dir, &doc);
    assert!(e.contains("light 0") && e.contains("degenerate"), "{e}");
}

#[test]
fn degenerate_cameras_are_refused() {
    let dir = temp_dir("scene-camera");
    let mut doc = cornell_json();
    let c = doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .position(|n| n.get("camera").is_some())
        .unwrap();
    doc["nodes"][c] = json!({"camera": 0, "translation": [0, 1, 3], "scale": [0, 0, 0]});
    let e = fails_on(&dir, &doc);
    assert!(e.contains("camera 0") && e.contains("singular"), "{e}");
    for (field, value, expect) in [
        ("znear", 1e-45, "znear"),
        ("yfov", 3.5, "yfov"),
        ("yfov", 1e-40, "yfov"),
        // Finite scale, but narrower than f32 tells a pixel's rays apart:
        // accepted before (a black image).
        (
            "yfov",
            1e-20,
            "yfov 1e-20 radians: the vertical field of view must be between",
        ),
        // A znear that is a normal float but underflows against the scene.
        ("znear", 1e-35, "depths would underflow"),
    ] {
        let mut doc = cornell_json();
        doc["cameras"][0]["perspective"][field] = json!(value);
        let e = fails_on(&dir, &doc);
        assert!(e.contains(expect), "{field} {value}: {e}");
        assert!(
            expect == "depths would underflow" || e.contains("camera 0"),
            "{e}"
        );
    }
}

#[test]
fn unsupported_required_extension() {
    let dir = temp_dir("scene-ext");
    let mut doc = cornell_json();
    doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let e = fails_on(&dir, &doc);
    assert!(e.contains("KHR_draco_mesh_compression"), "{e}");
}

#[test]
fn non_triangle_primitives_are_skipped_with_a_warning() {
    let dir = temp_dir("scene-lines");
    let mut doc = cornell_json();
    doc["meshes"][0]["primitives"][0]["mode"] = json!(1); // LINES
    write_scene(&dir, &doc);
    let ran = Isr::tiny(&dir).args(["--scene", "scene.gltf"]).succeeds();
    assert!(
        ran.stderr.contains("warning:") && ran.stderr.contains("skipped: mode Lines"),
        "{}",
        ran.stderr
    );
}

#[test]
fn a_bad_glb_header_is_a_glb_error() {
    let dir = temp_dir("scene-glb");
    let good = Doc::triangle().glb();
    let with = |at: usize, bytes: &[u8]| {
        let mut b = good.clone();
        b[at..at + bytes.len()].copy_from_slice(bytes);
        b
    };
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (with(0, b"glTX"), "does not start with the GLB magic"),
        (with(4, &[1]), "GLB version 1 is not supported"),
        (good[..good.len() - 8].to_vec(), "truncated"),
        (good[..10].to_vec(), "shorter than the 12-byte GLB header"),
    ];
    for (bytes, expect) in cases {
        std::fs::write(dir.join("s.glb"), &bytes).unwrap();
        let e = Isr::tiny(&dir).args(["--scene", "s.glb"]).fails();
        assert!(
            e.contains("not a valid GLB file") && e.contains(expect) && !e.contains("JSON"),
            "{e}"
        );
    }
    // The good one renders.
    std::fs::write(dir.join("s.glb"), &good).unwrap();
    Isr::tiny(&dir).args(["--scene", "s.glb"]).succeeds();
}

#[test]
fn huge_scenes_without_light_and_camera_are_refused_not_rendered_as_nan() {
    let dir = temp_dir("scene-huge");
    for scale in [1e18f64, 1e30] {
        let e = fails_on(&dir, &cornell_scaled_without_camera_and_light(scale));
        assert!(
            e.contains("the scene is too large") && e.contains("coordinates up to 1e6 m"),
            "{e}"
        );
    }
}

#[test]
fn a_texture_too_large_says_its_size_before_decoding() {
    let dir = temp_dir("scene-big-texture");
    std::fs::write(dir.join("big.png"), png_header_only(16384, 16384)).unwrap();
    std::fs::write(dir.join("wide.png"), png_header_only(100_000, 1)).unwrap();
    for (file, expect) in [
        ("big.png", "16384x16384 = 268435456 pixels"),
        (
            "wide.png",
            "100000x1 pixels; textures may be at most 16384x16384",
        ),
    ] {
        let mut doc = cornell_json();
        with_texture(&mut doc, json!({ "uri": file }));
        let e = fails_on(&dir, &doc);
        assert!(e.contains("image 0") && e.contains(expect), "{e}");
    }
}

/// A 40-level node DAG (2^40 + 1 instances from 4 KB) is refused from its
/// count alone: the message gives the exact count, which only the graph
/// (never an expansion) yields, and the process's peak memory is that of a
/// run refusing a malformed file, not of 2^20 instances (the limit) or more.
#[test]
fn a_node_dag_is_refused_before_it_is_expanded() {
    let dir = temp_dir("scene-dag");
    let doc = node_dag(40);
    assert!(serde_json::to_string(&doc).unwrap().len() < 4096);
    let ran = {
        write_scene(&dir, &doc);
        Isr::tiny(&dir).args(["--scene", "scene.gltf"]).run()
    };
    let peak = ran.peak_kib;
    let e = ran.clean_failure();
    assert!(
        e.contains("expands to 1099511627777 node instances") && e.contains("the limit is"),
        "{e}"
    );
    std::fs::write(dir.join("bad.gltf"), "{").unwrap();
    let malformed = Isr::tiny(&dir).args(["--scene", "bad.gltf"]).run();
    if let (Some(dag), Some(plain)) = (peak, malformed.peak_kib) {
        println!("peak resident memory: DAG {dag} KiB, malformed file {plain} KiB");
        // 2^20 instances of a 64-byte transform alone would be 64 MiB.
        assert!(
            dag < plain + 16 * 1024,
            "refusing the DAG took {dag} KiB at its peak, a malformed file {plain} KiB"
        );
    }
}
