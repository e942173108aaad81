//! Issue 14's reproducers about the files a scene names, run through the
//! release binary: URIs outside the scene's folder (absolute, `..`,
//! percent-encoded, other schemes, symbolic links), devices, FIFOs and
//! folders, and buffer files missing or shorter than declared. Each is a
//! clear message and a non-zero exit, never a panic, a hang or a leak of a
//! file's contents (`cli::Ran::clean_failure` checks all but the message).
mod common;

use common::cli::Isr;
use common::gltf::*;
use common::temp_dir;
use serde_json::{json, Value};
use std::path::Path;

/// Renders `dir/scene.gltf` holding `doc` (with `extra` options); expects a
/// clean failure and returns its message.
fn fails_on(dir: &Path, doc: &Value, extra: &[&str]) -> String {
    write_scene(dir, doc);
    Isr::tiny(dir)
        .args(["--scene", "scene.gltf"])
        .args(extra)
        .fails()
}

/// The Cornell box with buffer 0 read from `uri`.
fn cornell_with_buffer_uri(uri: &str) -> Value {
    let mut doc = cornell_json();
    doc["buffers"][0]["uri"] = json!(uri);
    doc
}

#[test]
fn a_missing_scene_file_is_named() {
    let dir = temp_dir("uri-missing-scene");
    let e = Isr::tiny(&dir)
        .args(["--scene", "/nonexistent/scene.gltf"])
        .fails();
    assert!(
        e.contains("cannot read scene file /nonexistent/scene.gltf"),
        "{e}"
    );
}

#[test]
fn a_missing_buffer_file_is_named() {
    let dir = temp_dir("uri-missing-buffer");
    let e = fails_on(&dir, &cornell_with_buffer_uri("missing.bin"), &[]);
    assert!(
        e.contains("reading buffer 0 (missing.bin)") && e.contains("cannot read"),
        "{e}"
    );
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
    with_texture(&mut doc, json!({"uri": "/etc/passwd"}));
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
    let e = Isr::tiny(&dir).args(["--scene", "pipe.bin"]).fails();
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
    let e = Isr::tiny(&dir).args(["--scene", "/dev/zero"]).fails();
    assert!(e.contains("is a device"), "{e}");
}

#[test]
fn allow_outside_uris_reads_a_buffer_beside_the_folder() {
    let dir = temp_dir("uri-allowed");
    let scene_dir = dir.join("scene");
    std::fs::create_dir_all(&scene_dir).unwrap();
    let doc = cornell_json();
    std::fs::write(dir.join("box.bin"), cornell_bin(&doc)).unwrap();
    let mut doc = doc;
    doc["buffers"][0]["uri"] = json!("../box.bin");
    let e = fails_on(&scene_dir, &doc, &[]);
    assert!(e.contains("climbs out"), "{e}");
    Isr::tiny(&scene_dir)
        .args(["--scene", "scene.gltf", "--allow-outside-uris"])
        .succeeds();
}

/// A buffer file shorter than its byteLength, and an embedded buffer whose
/// byteLength claims more than it holds.
#[test]
fn a_buffer_shorter_than_declared_is_refused() {
    let dir = temp_dir("uri-short");
    let doc = cornell_json();
    let bin = cornell_bin(&doc);
    std::fs::write(dir.join("short.bin"), &bin[..bin.len() - 8]).unwrap();
    let mut file = doc.clone();
    file["buffers"][0]["uri"] = json!("short.bin");
    let e = fails_on(&dir, &file, &[]);
    assert!(
        e.contains("buffer 0") && e.contains("declares byteLength") && e.contains("truncated"),
        "{e}"
    );
    let mut embedded = doc;
    embedded["buffers"][0]["byteLength"] = json!(bin.len() + 64);
    let e = fails_on(&dir, &embedded, &[]);
    assert!(e.contains("truncated"), "{e}");
}
