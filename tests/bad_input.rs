//! Bad input gets a clear message and a non-zero exit, never a panic.
mod common;

use common::{bin, clean_failure};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("isr-bad-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `isr render` with `args` at a tiny size, expects failure, returns stderr.
fn fails(dir: &Path, args: &[&str]) -> String {
    let out = bin()
        .arg("render")
        .args(["--frames", "1"])
        .args(args)
        .arg("--out")
        .arg(dir.join("o.exr"))
        .arg("--png")
        .arg(dir.join("o.png"))
        .output()
        .unwrap();
    clean_failure(&out, args)
}

/// The built-in Cornell box as glTF JSON, to be broken by each test.
fn cornell_json() -> Value {
    let text = isr::scene::export::to_gltf_json(&isr::scene::cornell::cornell_box()).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Writes `doc` and returns render arguments for it at a tiny size.
fn write_gltf(dir: &Path, doc: &Value) -> Vec<String> {
    let p = dir.join("scene.gltf");
    std::fs::write(&p, serde_json::to_string(doc).unwrap()).unwrap();
    let mut args: Vec<String> = small().iter().map(|s| s.to_string()).collect();
    args.extend([
        "--rsm".into(),
        "32".into(),
        "--scene".into(),
        p.to_string_lossy().into_owned(),
    ]);
    args
}

fn fails_on(dir: &Path, doc: &Value) -> String {
    let args = write_gltf(dir, doc);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    fails(dir, &args)
}

fn small() -> [&'static str; 4] {
    ["--width", "32", "--height", "32"]
}

#[test]
fn missing_scene_file() {
    let dir = temp_dir("missing");
    let e = fails(
        &dir,
        &[
            "--width",
            "32",
            "--height",
            "32",
            "--scene",
            "/nonexistent/scene.gltf",
        ],
    );
    assert!(
        e.contains("cannot read scene file /nonexistent/scene.gltf"),
        "{e}"
    );
}

#[test]
fn malformed_json() {
    let dir = temp_dir("json");
    let p = dir.join("bad.gltf");
    std::fs::write(&p, "{ \"asset\": { \"version\": \"2.0\" }, ").unwrap();
    let e = fails(
        &dir,
        &[
            "--width",
            "32",
            "--height",
            "32",
            "--scene",
            p.to_str().unwrap(),
        ],
    );
    assert!(e.contains("not a valid glTF 2.0 file"), "{e}");
}

#[test]
fn buffer_file_missing() {
    let dir = temp_dir("nobuf");
    let mut doc = cornell_json();
    doc["buffers"][0]["uri"] = json!("missing.bin");
    let e = fails_on(&dir, &doc);
    assert!(
        e.contains("reading buffer 0 (missing.bin)") && e.contains("cannot read"),
        "{e}"
    );
}

#[test]
fn buffer_too_short() {
    let dir = temp_dir("short");
    let mut doc = cornell_json();
    let len = doc["buffers"][0]["byteLength"].as_u64().unwrap();
    doc["buffers"][0]["byteLength"] = json!(len + 64);
    let e = fails_on(&dir, &doc);
    assert!(e.contains("truncated"), "{e}");
}

#[test]
fn buffer_view_past_the_end_of_its_buffer() {
    let dir = temp_dir("view");
    let mut doc = cornell_json();
    let len = doc["buffers"][0]["byteLength"].as_u64().unwrap();
    doc["bufferViews"][0]["byteOffset"] = json!(len - 4);
    let e = fails_on(&dir, &doc);
    assert!(e.contains("loading scene"), "{e}");
}

#[test]
fn non_finite_positions() {
    let dir = temp_dir("nan");
    let mut scene = isr::scene::cornell::cornell_box();
    scene.meshes[2].vertices[1].position[1] = f32::NAN;
    let doc: Value =
        serde_json::from_str(&isr::scene::export::to_gltf_json(&scene).unwrap()).unwrap();
    let e = fails_on(&dir, &doc);
    assert!(e.contains("non-finite position"), "{e}");
}

#[test]
fn bad_light_values_are_refused_with_what_is_wrong() {
    let spot = |inner: f64, outer: f64| {
        json!({"type": "spot", "intensity": 5.0,
            "spot": {"innerConeAngle": inner, "outerConeAngle": outer}})
    };
    let cases = [
        // (light, what the message must name)
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
    for (i, (light, what)) in cases.into_iter().enumerate() {
        let dir = temp_dir(&format!("light{i}"));
        let mut doc = cornell_json();
        doc["extensions"]["KHR_lights_punctual"]["lights"][0] = light.clone();
        let e = fails_on(&dir, &doc);
        assert!(e.contains("light 0") && e.contains(what), "{light}: {e}");
    }
}

#[test]
fn unsupported_required_extension() {
    let dir = temp_dir("ext");
    let mut doc = cornell_json();
    doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let e = fails_on(&dir, &doc);
    assert!(e.contains("KHR_draco_mesh_compression"), "{e}");
}

#[test]
fn non_triangle_primitives_are_skipped_with_a_warning() {
    let dir = temp_dir("lines");
    let mut doc = cornell_json();
    doc["meshes"][0]["primitives"][0]["mode"] = json!(1); // LINES
    let out = bin()
        .args(["render", "--frames", "1"])
        .args(write_gltf(&dir, &doc))
        .arg("--out")
        .arg(dir.join("o.exr"))
        .arg("--png")
        .arg(dir.join("o.png"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning:") && stderr.contains("skipped: mode Lines"),
        "{stderr}"
    );
}

#[test]
fn zero_resolution() {
    let dir = temp_dir("zero");
    let e = fails(&dir, &["--width", "0", "--height", "32", "--rsm", "32"]);
    assert!(e.contains("resolution 0x32 is empty"), "{e}");
}

#[test]
fn huge_resolution() {
    let dir = temp_dir("huge");
    let e = fails(
        &dir,
        &["--width", "1000000", "--height", "32", "--rsm", "32"],
    );
    assert!(
        e.contains("exceeds what") && e.contains("--width/--height"),
        "{e}"
    );
}

#[test]
fn rsm_not_a_power_of_two() {
    let dir = temp_dir("rsm");
    let e = fails(&dir, &["--width", "32", "--height", "32", "--rsm", "100"]);
    assert!(e.contains("power of two"), "{e}");
}

#[test]
fn no_vulkan_device_says_how_to_install_a_driver() {
    let dir = temp_dir("nodevice");
    let out = bin()
        .args(["render", "--frames", "1"])
        .args(small())
        .arg("--out")
        .arg(dir.join("o.exr"))
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        stderr.contains("mesa-vulkan-drivers"),
        "the message should say how to install a driver:\n{stderr}"
    );
}

#[test]
fn too_many_levels() {
    let dir = temp_dir("levels");
    let e = fails(
        &dir,
        &[
            "--width", "32", "--height", "32", "--rsm", "32", "--levels", "40",
        ],
    );
    assert!(e.contains("--levels 40"), "{e}");
}

#[test]
fn vpls_not_a_power_of_four() {
    let dir = temp_dir("vpls");
    let e = fails(
        &dir,
        &[
            "--width", "32", "--height", "32", "--rsm", "32", "--vpls", "200",
        ],
    );
    assert!(e.contains("power of 4"), "{e}");
}

#[test]
fn multires_splat_refuses_stencil_off() {
    let dir = temp_dir("splat-stencil");
    let e = fails(
        &dir,
        &[
            "--width",
            "32",
            "--height",
            "32",
            "--rsm",
            "32",
            "--method",
            "multires-splat",
            "--stencil",
            "off",
        ],
    );
    assert!(e.contains("--stencil off"), "{e}");
}
