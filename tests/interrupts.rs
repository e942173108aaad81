//! Interrupted runs (issue 29, item 7): SIGINT or SIGTERM during a
//! `--sequence` removes the temporaries of unfinished writes and ends the
//! process as the signal would have; the frames already written are whole.
//! A temporary left by a run that could not clean up (SIGKILL) is removed by
//! the next run that writes into its folder, once its PID is not alive.
//!
//! `ISR_TEST_WRITE_PAUSE_MS` (the test hook of `output::write_atomic`) holds
//! every write between its last byte and its rename, so the signal is sent
//! while a temporary certainly exists, however loaded the machine.
#![cfg(unix)]
mod common;

use common::cli::{Isr, Running};
use common::temp_dir;
use std::os::unix::process::ExitStatusExt as _;
use std::path::Path;
use std::time::{Duration, Instant};

/// The hidden temporaries in `dir` (`.NAME.PID-N.tmp`).
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|d| {
            d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with('.') && n.ends_with(".tmp"))
                .collect()
        })
        .unwrap_or_default()
}

/// `isr render` of 32x32 frames (RSM 32) in `dir`.
fn small(dir: &Path) -> Isr {
    Isr::render(dir).args(["--width", "32", "--height", "32", "--rsm", "32"])
}

/// `isr render --sequence seq --frames 20` in `dir`, every write held.
fn sequence(dir: &Path) -> Running {
    small(dir)
        .args(["--frames", "20", "--sequence", "seq"])
        .env("ISR_TEST_WRITE_PAUSE_MS", "300")
        .hang_guard(Duration::from_secs(120))
        .default_signals()
        .spawn()
}

/// Waits (within a guard far above what it takes) until the first frame is
/// written and a later write's temporary exists.
fn wait_for_a_temporary(run: &Running, seq: &Path) {
    let started = Instant::now();
    let ready = || seq.join("frame_0000.png").exists() && !temporaries(seq).is_empty();
    while !ready() {
        assert!(!run.has_ended(), "isr ended before it was interrupted");
        assert!(
            started.elapsed() < Duration::from_secs(100),
            "no temporary appeared"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn interrupt(name: &str, signal: i32) {
    let dir = temp_dir(name);
    let seq = dir.join("seq");
    let run = sequence(&dir);
    wait_for_a_temporary(&run, &seq);
    run.signal(signal);
    let ran = run.wait();
    assert_eq!(
        ran.status.signal(),
        Some(signal),
        "isr did not end by the signal ({}):\n{}",
        ran.status,
        ran.stderr
    );
    assert!(
        temporaries(&seq).is_empty(),
        "temporaries left: {:?}\n{}",
        temporaries(&seq),
        ran.stderr
    );
    assert!(
        ran.stderr.contains("interrupted by SIG")
            && ran.stderr.contains(" complete; ")
            && ran.stderr.contains("timings.json was not written"),
        "{}",
        ran.stderr
    );
    assert!(!seq.join("timings.json").exists());
    // Every visible frame is whole.
    let mut frames = 0;
    for e in std::fs::read_dir(&seq).unwrap() {
        let path = e.unwrap().path();
        match path.extension().and_then(|e| e.to_str()) {
            Some("png") => {
                image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                frames += 1;
            }
            Some("exr") => {
                exr::prelude::read_all_data_from_file(&path)
                    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            }
            _ => panic!("unexpected file {}", path.display()),
        }
    }
    assert!((1..20).contains(&frames), "{frames} frames");
}

#[test]
fn sigint_mid_sequence_removes_its_temporaries() {
    interrupt("int-sigint", libc::SIGINT);
}

#[test]
fn sigterm_mid_sequence_removes_its_temporaries() {
    interrupt("int-sigterm", libc::SIGTERM);
}

/// A PID that is not alive: a process that ran and was reaped.
fn dead_pid() -> u32 {
    let mut child = std::process::Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    pid
}

#[test]
fn a_later_run_removes_stale_temporaries_of_dead_runs_only() {
    let dir = temp_dir("int-stale");
    let seq = dir.join("seq");
    std::fs::create_dir_all(&seq).unwrap();
    let dead = dead_pid();
    let alive = std::process::id();
    // What SIGKILL left mid-write (the frame, the GIF, the timings), of a
    // dead run and of a live one (this test), and files of other patterns.
    let stale = [
        format!(".frame_0007.exr.{dead}-13.tmp"),
        format!(".frame_0007.png.{dead}-14.tmp"),
        format!(".timings.json.{dead}-40.tmp"),
        format!(".sequence.gif.{dead}-41.tmp"),
    ];
    let kept = [
        format!(".frame_0007.exr.{alive}-13.tmp"),
        format!(".notes.txt.{dead}-0.tmp"),
        format!(".frame_0007.exr.{dead}.tmp"),
        "frame_0007.exr.tmp".to_string(),
    ];
    for n in stale.iter().chain(&kept) {
        std::fs::write(seq.join(n), vec![0u8; 4096]).unwrap();
    }
    small(&dir)
        .args(["--frames", "2", "--sequence", "seq"])
        .succeeds();
    let mut left = temporaries(&seq);
    left.extend(
        std::fs::read_dir(&seq)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp") && !n.starts_with('.')),
    );
    left.sort();
    let mut expected = kept.to_vec();
    expected.sort();
    assert_eq!(left, expected, "stale temporaries of dead runs are removed");
    // A plain render sweeps the folder of each output the same way.
    let stale_out = format!(".r.exr.{dead}-2.tmp");
    std::fs::write(dir.join(&stale_out), b"x").unwrap();
    Isr::tiny(&dir)
        .args(["--out", "r.exr", "--png", "r.png"])
        .succeeds();
    assert!(!dir.join(&stale_out).exists());
}
