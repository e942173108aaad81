//! Outputs that would destroy files or cannot be written, checked before
//! anything renders, and GPU failures in the middle of a run (injected with
//! `ISR_INJECT_FAULT`, the test hook for what real GPUs do and lavapipe does
//! not), which leave old files untouched and say which frames were kept.
mod common;

use common::cli::Isr;
use common::temp_dir;
use std::path::Path;

/// Asserts that `e` came before rendering began.
fn before_rendering(e: &str) {
    assert!(
        !e.contains("rendering"),
        "checked only after rendering:\n{e}"
    );
}

#[test]
fn an_unsupported_output_extension_leaves_the_file_intact() {
    let dir = temp_dir("out-ext");
    std::fs::write(dir.join("some.exr"), b"precious").unwrap();
    let e = Isr::tiny(&dir)
        .args(["--png", "some.exr", "--out", "o.exr"])
        .fails();
    assert!(e.contains("--png some.exr") && e.contains(".png"), "{e}");
    assert_eq!(std::fs::read(dir.join("some.exr")).unwrap(), b"precious");
    before_rendering(&e);
}

#[test]
fn two_outputs_on_one_path_are_refused_before_rendering() {
    let dir = temp_dir("out-same");
    std::fs::write(dir.join("x.exr"), b"precious").unwrap();
    let e = Isr::tiny(&dir)
        .args(["--out", "x.exr", "--png", "x.exr"])
        .fails();
    assert!(e.contains("must end in .png"), "{e}");
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("x.exr", dir.join("x.png")).unwrap();
        let e = Isr::tiny(&dir)
            .args(["--out", "x.exr", "--png", "x.png"])
            .fails();
        assert!(e.contains("are the same file"), "{e}");
    }
    assert_eq!(std::fs::read(dir.join("x.exr")).unwrap(), b"precious");
}

#[test]
fn unwritable_and_directory_outputs_are_refused_before_rendering() {
    let dir = temp_dir("out-dir");
    std::fs::create_dir_all(dir.join("d.png")).unwrap();
    let e = Isr::tiny(&dir)
        .args(["--out", "o.exr", "--png", "d.png"])
        .fails();
    assert!(e.contains("--png d.png is a directory"), "{e}");
    std::fs::write(dir.join("file"), b"").unwrap();
    let e = Isr::tiny(&dir)
        .args(["--out", "file/o.exr", "--png", "o.png"])
        .fails();
    assert!(e.contains("cannot create its folder"), "{e}");
    let e = Isr::tiny(&dir)
        .args([
            "--out",
            "o.exr",
            "--png",
            "o.png",
            "--timings",
            "file/t.json",
        ])
        .fails();
    assert!(e.contains("--timings file/t.json"), "{e}");
    before_rendering(&e);
}

#[test]
fn debug_views_and_sequence_folders_are_checked_before_rendering() {
    let dir = temp_dir("out-debug");
    let e = Isr::tiny(&dir)
        .args(["--method", "rsm-gather", "--debug-view", "levels"])
        .fails();
    assert!(
        e.contains("--debug-view levels") && e.contains("rsm-gather"),
        "{e}"
    );
    std::fs::create_dir_all(dir.join("r-levels.png")).unwrap();
    let e = Isr::tiny(&dir)
        .args(["--out", "r.exr", "--png", "r.png", "--debug-view", "levels"])
        .fails();
    assert!(
        e.contains("--debug-view r-levels.png is a directory"),
        "{e}"
    );
    std::fs::write(dir.join("seq"), b"a file").unwrap();
    let e = Isr::tiny(&dir).args(["--sequence", "seq"]).fails();
    assert!(
        e.contains("--sequence seq") && e.contains("not a folder"),
        "{e}"
    );
    before_rendering(&e);
}

/// Renders 40 frames with submission `fault` failing; expects a clean
/// failure and returns its message.
fn with_fault(dir: &Path, fault: &str, args: &[&str]) -> String {
    Isr::render(dir)
        .args([
            "--width", "32", "--height", "32", "--rsm", "32", "--frames", "40",
        ])
        .args(args)
        .env("ISR_INJECT_FAULT", fault)
        .fails()
}

#[test]
fn device_loss_mid_run_leaves_old_outputs_and_says_so() {
    let dir = temp_dir("out-device-lost");
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
    let dir = temp_dir("out-oom-sequence");
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
