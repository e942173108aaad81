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

/// Issue 29, item 9: an output that is a symbolic link is written through
/// to its target (the link stays a link), also when the target does not
/// exist yet; two outputs whose links meet are one file.
#[cfg(unix)]
#[test]
fn outputs_through_symbolic_links_write_the_target() {
    let dir = temp_dir("out-symlink");
    std::fs::create_dir_all(dir.join("real")).unwrap();
    std::fs::write(dir.join("real/target.exr"), b"old").unwrap();
    std::os::unix::fs::symlink("real/target.exr", dir.join("link.exr")).unwrap();
    // A link to a link to a file that does not exist yet.
    std::os::unix::fs::symlink("real/new.png", dir.join("hop.png")).unwrap();
    std::os::unix::fs::symlink("hop.png", dir.join("link.png")).unwrap();
    Isr::tiny(&dir)
        .args(["--out", "link.exr", "--png", "link.png"])
        .succeeds();
    for (link, target) in [
        ("link.exr", "real/target.exr"),
        ("link.png", "hop.png"),
        ("hop.png", "real/new.png"),
    ] {
        let meta = std::fs::symlink_metadata(dir.join(link)).unwrap();
        assert!(meta.file_type().is_symlink(), "{link} was replaced");
        assert_eq!(
            std::fs::read_link(dir.join(link)).unwrap(),
            Path::new(target)
        );
    }
    exr::prelude::read_all_data_from_file(dir.join("real/target.exr"))
        .expect("the link's target holds the new image");
    image::open(dir.join("real/new.png")).expect("the dangling link's target was created");
    let left: Vec<_> = std::fs::read_dir(dir.join("real"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "temporary files left: {left:?}");
    // A dangling link and the file it names are the same output.
    std::os::unix::fs::symlink("real/y.exr", dir.join("x.png")).unwrap();
    let e = Isr::tiny(&dir)
        .args(["--out", "real/y.exr", "--png", "x.png"])
        .fails();
    assert!(e.contains("are the same file"), "{e}");
    before_rendering(&e);
}

/// Issue 29, item 10: a file name the file system takes is written however
/// long (the temporary's name is kept within the limit); one it cannot take
/// is refused before rendering, saying that the name is too long.
#[test]
fn long_output_names_are_written_or_refused_as_too_long() {
    let dir = temp_dir("out-long-name");
    let name = format!("{}.exr", "a".repeat(250));
    assert_eq!(name.len(), 254);
    Isr::tiny(&dir)
        .args(["--png", "p.png"])
        .arg("--out")
        .arg(&name)
        .succeeds();
    exr::prelude::read_all_data_from_file(dir.join(&name)).unwrap();
    // Multi-byte characters: 127 two-byte ones and ".png", 258 bytes.
    let accented = format!("{}.png", "é".repeat(127));
    let e = Isr::tiny(&dir)
        .args(["--out", "o.exr"])
        .arg("--png")
        .arg(&accented)
        .fails();
    assert!(
        e.contains("the file name is 258 bytes long") && e.contains("at most 255"),
        "{e}"
    );
    assert!(!e.contains("not writable"), "{e}");
    before_rendering(&e);
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "temporary files left: {left:?}");
}
