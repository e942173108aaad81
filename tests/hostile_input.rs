//! Issue 14's reproducers, each run through the release binary: scene files
//! that name files outside their folder, devices and FIFOs, a node DAG, bad
//! GLB headers, degenerate cameras and lights, outputs that would destroy
//! files, and option values that hung or were misread. Each must give a clear
//! message and a non-zero exit, never a panic, a hang or a leak of a file's
//! contents.
mod common;
#[path = "support/gltf.rs"]
mod gltf;

use common::{bin, clean_failure};
use gltf::*;
use serde_json::{json, Value};
use std::path::Path;
use std::process::Output;
use std::time::{Duration, Instant};

/// Runs `isr render` with a deadline: a hang fails the test instead of the
/// whole run.
fn run(args: &[&str], dir: &Path) -> (Output, Duration) {
    let mut child = bin()
        .arg("render")
        .args([
            "--frames", "1", "--width", "32", "--height", "32", "--rsm", "32",
        ])
        .args(args)
        .current_dir(dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("isr render {args:?} hung");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    (child.wait_with_output().unwrap(), started.elapsed())
}

/// Expects failure with a clear error and no panic; returns stderr.
fn fails(dir: &Path, args: &[&str]) -> String {
    let (out, _) = run(args, dir);
    let stderr = clean_failure(&out, args);
    // Nothing of /etc/passwd (or any file's bytes) in the message.
    assert!(!stderr.contains("root:"), "file contents leaked:\n{stderr}");
    stderr
}

/// Writes `doc` as dir/scene.gltf and expects the render to fail.
fn fails_on(dir: &Path, doc: &Value, extra: &[&str]) -> String {
    std::fs::write(dir.join("scene.gltf"), serde_json::to_string(doc).unwrap()).unwrap();
    let mut args = vec!["--scene", "scene.gltf", "--out", "o.exr", "--png", "o.png"];
    args.extend(extra);
    fails(dir, &args)
}

/// The Cornell box with buffer 0 read from `uri`.
fn cornell_with_buffer_uri(uri: &str) -> Value {
    let mut doc = cornell_json();
    doc["buffers"][0]["uri"] = json!(uri);
    doc
}

#[test]
fn absolute_buffer_uri_is_refused() {
    let dir = temp_dir("uri-abs");
    let e = fails_on(&dir, &cornell_with_buffer_uri("/etc/passwd"), &[]);
    assert!(
        e.contains("buffer 0 (/etc/passwd)")
            && e.contains("absolute paths are refused")
            && e.contains("--allow-outside-uris"),
        "{e}"
    );
}

#[test]
fn uris_climbing_out_of_the_folder_are_refused() {
    let dir = temp_dir("uri-dotdot");
    for uri in [
        "../../../../etc/passwd",
        "%2e%2e/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
        "sub/../../x.bin",
        "..%2F..%2F..%2F..%2Fetc%2Fpasswd",
    ] {
        let e = fails_on(&dir, &cornell_with_buffer_uri(uri), &[]);
        assert!(
            e.contains(&format!("buffer 0 ({uri})")) && e.contains("climbs out"),
            "{e}"
        );
    }
}

#[test]
fn other_schemes_are_refused() {
    let dir = temp_dir("uri-scheme");
    let e = fails_on(&dir, &cornell_with_buffer_uri("file:///etc/passwd"), &[]);
    assert!(e.contains("file: URIs are refused"), "{e}");
    let e = fails_on(
        &dir,
        &cornell_with_buffer_uri("https://example.com/b.bin"),
        &[],
    );
    assert!(e.contains("URI scheme https"), "{e}");
}

#[cfg(unix)]
#[test]
fn symbolic_links_out_of_the_folder_are_refused() {
    let dir = temp_dir("uri-symlink");
    std::os::unix::fs::symlink("/etc/passwd", dir.join("link.bin")).unwrap();
    let e = fails_on(&dir, &cornell_with_buffer_uri("link.bin"), &[]);
    assert!(e.contains("symbolic link"), "{e}");
}

#[test]
fn image_uris_follow_the_same_policy() {
    let dir = temp_dir("uri-image");
    let mut doc = cornell_json();
    doc["images"] = json!([{"uri": "/etc/passwd"}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
    let e = fails_on(&dir, &doc, &[]);
    assert!(
        e.contains("image 0") && e.contains("absolute paths are refused"),
        "{e}"
    );
}

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_without_blocking() {
    let dir = temp_dir("uri-fifo");
    let status = std::process::Command::new("mkfifo")
        .arg(dir.join("pipe.bin"))
        .status()
        .unwrap();
    assert!(status.success());
    let e = fails_on(&dir, &cornell_with_buffer_uri("pipe.bin"), &[]);
    assert!(
        e.contains("a FIFO") && e.contains("only regular files"),
        "{e}"
    );
    // Also as the scene file itself.
    let e = fails(&dir, &["--scene", "pipe.bin"]);
    assert!(e.contains("a FIFO"), "{e}");
}

#[test]
fn devices_and_folders_are_refused_even_when_outside_uris_are_allowed() {
    let dir = temp_dir("uri-dev");
    let e = fails_on(&dir, &cornell_with_buffer_uri("/dev/zero"), &[]);
    assert!(e.contains("absolute paths are refused"), "{e}");
    let e = fails_on(
        &dir,
        &cornell_with_buffer_uri("/dev/zero"),
        &["--allow-outside-uris"],
    );
    assert!(e.contains("/dev/zero is a device"), "{e}");
    std::fs::create_dir_all(dir.join("folder.bin")).unwrap();
    let e = fails_on(&dir, &cornell_with_buffer_uri("folder.bin"), &[]);
    assert!(e.contains("is a directory"), "{e}");
    let e = fails(&dir, &["--scene", "/dev/zero"]);
    assert!(e.contains("is a device"), "{e}");
}

#[test]
fn allow_outside_uris_reads_a_buffer_beside_the_folder() {
    let dir = temp_dir("uri-allowed");
    let scene_dir = dir.join("scene");
    std::fs::create_dir_all(&scene_dir).unwrap();
    let doc = cornell_json();
    std::fs::write(dir.join("box.bin"), cornell_bin(&doc)).unwrap();
    let doc = {
        let mut d = doc;
        d["buffers"][0]["uri"] = json!("../box.bin");
        d
    };
    let e = fails_on(&scene_dir, &doc, &[]);
    assert!(e.contains("climbs out"), "{e}");
    let (out, _) = run(
        &[
            "--scene",
            "scene.gltf",
            "--out",
            "o.exr",
            "--png",
            "o.png",
            "--allow-outside-uris",
        ],
        &scene_dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_buffer_file_shorter_than_declared_is_refused() {
    let dir = temp_dir("uri-short");
    let doc = cornell_json();
    let bin = cornell_bin(&doc);
    std::fs::write(dir.join("short.bin"), &bin[..bin.len() - 8]).unwrap();
    let mut doc = doc;
    doc["buffers"][0]["uri"] = json!("short.bin");
    let e = fails_on(&dir, &doc, &[]);
    assert!(
        e.contains("buffer 0") && e.contains("declares byteLength") && e.contains("truncated"),
        "{e}"
    );
}

#[test]
fn a_node_dag_is_refused_before_it_is_expanded() {
    let dir = temp_dir("dag");
    let doc = node_dag(40);
    assert!(serde_json::to_string(&doc).unwrap().len() < 4096);
    std::fs::write(dir.join("scene.gltf"), serde_json::to_string(&doc).unwrap()).unwrap();
    let (out, took) = run(
        &["--scene", "scene.gltf", "--out", "o.exr", "--png", "o.png"],
        &dir,
    );
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && !e.contains("panicked"), "{e}");
    assert!(
        e.contains("expands to 1099511627777 node instances") && e.contains("the limit is"),
        "{e}"
    );
    assert!(took < Duration::from_secs(5), "took {took:?}");
}

#[test]
fn a_bad_glb_header_is_a_glb_error() {
    let dir = temp_dir("glb");
    let (mut doc, bin) = triangle_doc();
    doc["buffers"][0] = json!({"byteLength": bin.len()});
    let good = glb(&doc, Some(&bin));
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (
            {
                let mut b = good.clone();
                b[..4].copy_from_slice(b"glTX");
                b
            },
            "does not start with the GLB magic",
        ),
        (
            {
                let mut b = good.clone();
                b[4] = 1;
                b
            },
            "GLB version 1 is not supported",
        ),
        (good[..good.len() - 8].to_vec(), "truncated"),
        (good[..10].to_vec(), "shorter than the 12-byte GLB header"),
    ];
    for (bytes, expect) in cases {
        std::fs::write(dir.join("s.glb"), &bytes).unwrap();
        let e = fails(
            &dir,
            &["--scene", "s.glb", "--out", "o.exr", "--png", "o.png"],
        );
        assert!(
            e.contains("not a valid GLB file") && e.contains(expect) && !e.contains("JSON"),
            "{e}"
        );
    }
    // The good one renders.
    std::fs::write(dir.join("s.glb"), &good).unwrap();
    let (out, _) = run(
        &["--scene", "s.glb", "--out", "o.exr", "--png", "o.png"],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn degenerate_cameras_are_refused() {
    let dir = temp_dir("camera");
    let camera_node = |doc: &Value| {
        doc["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .position(|n| n.get("camera").is_some())
            .unwrap()
    };
    let mut doc = cornell_json();
    let c = camera_node(&doc);
    doc["nodes"][c] = json!({"camera": 0, "translation": [0, 1, 3], "scale": [0, 0, 0]});
    let e = fails_on(&dir, &doc, &[]);
    assert!(e.contains("camera 0") && e.contains("singular"), "{e}");
    for (field, value, expect) in [
        ("znear", 1e-45, "znear"),
        ("yfov", 3.5, "yfov"),
        ("yfov", 1e-40, "yfov"),
    ] {
        let mut doc = cornell_json();
        doc["cameras"][0]["perspective"][field] = json!(value);
        let e = fails_on(&dir, &doc, &[]);
        assert!(e.contains("camera 0") && e.contains(expect), "{e}");
    }
    // A znear that is a normal float but underflows against the scene.
    let mut doc = cornell_json();
    doc["cameras"][0]["perspective"]["znear"] = json!(1e-35);
    let e = fails_on(&dir, &doc, &[]);
    assert!(e.contains("depths would underflow"), "{e}");
}

#[test]
fn degenerate_lights_are_refused() {
    let dir = temp_dir("light");
    let cases = [
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
    for (patch, expect) in cases {
        let mut doc = cornell_json();
        let light = &mut doc["extensions"]["KHR_lights_punctual"]["lights"][0];
        for (k, v) in patch.as_object().unwrap() {
            light[k] = v.clone();
        }
        let e = fails_on(&dir, &doc, &[]);
        assert!(e.contains("light 0") && e.contains(expect), "{e}");
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
    let e = fails_on(&dir, &doc, &[]);
    assert!(e.contains("light 0") && e.contains("degenerate"), "{e}");
}

#[test]
fn non_finite_normals_are_refused() {
    let dir = temp_dir("nan-normal");
    let mut scene = isr::scene::cornell::cornell_box();
    scene.meshes[1].vertices[2].normal = [f32::NAN, 0.0, 1.0];
    let doc: Value =
        serde_json::from_str(&isr::scene::export::to_gltf_json(&scene).unwrap()).unwrap();
    let e = fails_on(&dir, &doc, &[]);
    assert!(
        e.contains("mesh 1") && e.contains("vertex 2 has a non-finite normal"),
        "{e}"
    );
}

#[test]
fn attributes_of_the_wrong_type_are_refused() {
    let dir = temp_dir("types");
    // POSITION accessor 0 of mesh 0, NORMAL 1, indices 2 (the exporter's order).
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
        let e = fails_on(&dir, &doc, &[]);
        assert!(
            e.contains("mesh 0 (floor) primitive 0") && e.contains(expect) && e.contains(got),
            "{e}"
        );
    }
}

#[test]
fn huge_scenes_without_light_and_camera_are_refused_not_rendered_as_nan() {
    let dir = temp_dir("huge-scene");
    for scale in [1e18f64, 1e30] {
        let mut doc = cornell_json();
        let nodes = doc["nodes"].as_array_mut().unwrap();
        nodes.retain(|n| n.get("camera").is_none() && n.get("extensions").is_none());
        let n = nodes.len();
        nodes.push(json!({"children": (0..n).collect::<Vec<_>>(), "scale": [scale, scale, scale]}));
        doc["scenes"][0]["nodes"] = json!([n]);
        let e = fails_on(&dir, &doc, &[]);
        assert!(
            e.contains("the scene is too large") && e.contains("coordinates up to 1e6 m"),
            "{e}"
        );
    }
}

#[test]
fn a_texture_too_large_says_its_size_before_decoding() {
    let dir = temp_dir("big-texture");
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
        doc["images"] = json!([{ "uri": file }]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
        let e = fails_on(&dir, &doc, &[]);
        assert!(e.contains("image 0") && e.contains(expect), "{e}");
    }
}

#[test]
fn an_unsupported_output_extension_leaves_the_file_intact() {
    let dir = temp_dir("out-ext");
    std::fs::write(dir.join("some.exr"), b"precious").unwrap();
    let e = fails(&dir, &["--png", "some.exr", "--out", "o.exr"]);
    assert!(e.contains("--png some.exr") && e.contains(".png"), "{e}");
    assert_eq!(std::fs::read(dir.join("some.exr")).unwrap(), b"precious");
    assert!(
        !e.contains("rendering"),
        "checked only after rendering:\n{e}"
    );
}

#[test]
fn two_outputs_on_one_path_are_refused_before_rendering() {
    let dir = temp_dir("out-same");
    std::fs::write(dir.join("x.exr"), b"precious").unwrap();
    let e = fails(&dir, &["--out", "x.exr", "--png", "x.exr"]);
    assert!(e.contains("must end in .png"), "{e}");
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("x.exr", dir.join("x.png")).unwrap();
        let e = fails(&dir, &["--out", "x.exr", "--png", "x.png"]);
        assert!(e.contains("are the same file"), "{e}");
    }
    assert_eq!(std::fs::read(dir.join("x.exr")).unwrap(), b"precious");
}

#[test]
fn unwritable_and_directory_outputs_are_refused_before_rendering() {
    let dir = temp_dir("out-dir");
    std::fs::create_dir_all(dir.join("d.png")).unwrap();
    let e = fails(&dir, &["--out", "o.exr", "--png", "d.png"]);
    assert!(e.contains("--png d.png is a directory"), "{e}");
    std::fs::write(dir.join("file"), b"").unwrap();
    let e = fails(&dir, &["--out", "file/o.exr", "--png", "o.png"]);
    assert!(e.contains("cannot create its folder"), "{e}");
    let e = fails(
        &dir,
        &[
            "--out",
            "o.exr",
            "--png",
            "o.png",
            "--timings",
            "file/t.json",
        ],
    );
    assert!(e.contains("--timings file/t.json"), "{e}");
    {
        let e = &e;
        assert!(
            !e.contains("rendering"),
            "checked only after rendering:\n{e}"
        );
    }
}

#[test]
fn negative_option_values_reach_the_range_check() {
    let dir = temp_dir("negative");
    let e = fails(&dir, &["--tau", "-1", "--out", "o.exr", "--png", "o.png"]);
    assert!(
        e.contains("--tau -1") && !e.contains("unexpected argument"),
        "{e}"
    );
}

#[test]
fn spp_is_bounded() {
    let dir = temp_dir("spp");
    let (out, took) = run(
        &[
            "--method",
            "pathtrace",
            "--spp",
            "4294967295",
            "--out",
            "o.exr",
            "--png",
            "o.png",
        ],
        &dir,
    );
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{e}");
    assert!(e.contains("--spp") && e.contains("1..=65536"), "{e}");
    assert!(took < Duration::from_secs(5), "took {took:?}");
}

#[test]
fn debug_views_and_sequence_folders_are_checked_before_rendering() {
    let dir = temp_dir("debug-out");
    let e = fails(&dir, &["--method", "rsm-gather", "--debug-view", "levels"]);
    assert!(
        e.contains("--debug-view levels") && e.contains("rsm-gather"),
        "{e}"
    );
    std::fs::create_dir_all(dir.join("r-levels.png")).unwrap();
    let e = fails(
        &dir,
        &["--out", "r.exr", "--png", "r.png", "--debug-view", "levels"],
    );
    assert!(
        e.contains("--debug-view r-levels.png is a directory"),
        "{e}"
    );
    std::fs::write(dir.join("seq"), b"a file").unwrap();
    let e = fails(&dir, &["--sequence", "seq"]);
    assert!(
        e.contains("--sequence seq") && e.contains("not a folder"),
        "{e}"
    );
    assert!(
        !e.contains("rendering"),
        "checked only after rendering:\n{e}"
    );
}

#[test]
fn a_one_pixel_image_names_the_resolution_not_levels() {
    let dir = temp_dir("one-pixel");
    let one_pixel = |method: &str| {
        bin()
            .args([
                "render", "--width", "1", "--height", "1", "--rsm", "32", "--vpls", "16",
            ])
            .args([
                "--frames", "1", "--out", "o.exr", "--png", "o.png", "--method", method,
            ])
            .current_dir(&dir)
            .output()
            .unwrap()
    };
    let out = one_pixel("hisr");
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{e}");
    assert!(
        e.contains("resolution 1x1") && e.contains("at least 2x2") && !e.contains("--levels"),
        "{e}"
    );
    // Methods without the multiresolution buffer render one pixel.
    let out = one_pixel("rsm-gather");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs `isr render` with `ISR_INJECT_FAULT` (the test hook for what real GPUs
/// do and lavapipe does not): the given submission fails.
fn with_fault(dir: &Path, fault: &str, args: &[&str]) -> String {
    let out = bin()
        .arg("render")
        .args([
            "--width", "32", "--height", "32", "--rsm", "32", "--frames", "40",
        ])
        .args(args)
        .env("ISR_INJECT_FAULT", fault)
        .current_dir(dir)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    e
}

#[test]
fn device_loss_mid_run_leaves_old_outputs_and_says_so() {
    let dir = temp_dir("device-lost");
    for f in ["r.exr", "r.png", "t.json"] {
        std::fs::write(dir.join(f), b"old").unwrap();
    }
    // Submission 20 is well past the scene upload: frames are in flight.
    let e = with_fault(
        &dir,
        "device-lost:20",
        &["--out", "r.exr", "--png", "r.png", "--timings", "t.json"],
    );
    let finished: u32 = e
        .split("rendering failed after ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no frame count in:\n{e}"));
    assert!(
        (2..40).contains(&finished) && e.contains(" of 40 frames"),
        "the fault came before or after the frames:\n{e}"
    );
    assert!(
        e.contains("no output was written (existing files are untouched)")
            && e.contains("the GPU device was lost"),
        "{e}"
    );
    // The error starts its own line, not the progress bar's.
    assert!(e.lines().any(|l| l.starts_with("error:")), "{e}");
    for f in ["r.exr", "r.png", "t.json"] {
        assert_eq!(std::fs::read(dir.join(f)).unwrap(), b"old", "{f}");
    }
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 3, "temporary files left: {left:?}");
}

#[test]
fn out_of_memory_mid_sequence_names_the_frames_kept() {
    let dir = temp_dir("oom-sequence");
    let e = with_fault(&dir, "out-of-memory:20", &["--sequence", "seq"]);
    assert!(e.contains("the GPU ran out of memory"), "{e}");
    let kept: Vec<String> = std::fs::read_dir(dir.join("seq"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png"))
        .collect();
    assert!(!kept.is_empty(), "{e}");
    let last = kept.len() - 1;
    assert!(
        e.contains(&format!("rendering frame {} ", kept.len()))
            && e.contains(&format!("frames 0000 to {last:04} in seq are complete"))
            && e.contains("timings.json was not written"),
        "{e}\nkept {kept:?}"
    );
    assert!(!dir.join("seq/timings.json").exists());
    for name in &kept {
        image::open(dir.join("seq").join(name)).unwrap_or_else(|err| panic!("{name}: {err}"));
    }
    // A malformed hook is an error too, not ignored.
    let e = with_fault(&dir, "melt:1", &[]);
    assert!(e.contains("ISR_INJECT_FAULT=melt:1"), "{e}");
}
