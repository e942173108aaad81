//! `isr bench`'s folder as it may be found (issue 29, items 6 and 8): a
//! journal cut anywhere, even inside a character, or holding bytes that are
//! not a row, is read with those lines skipped and named; outputs that are
//! links to devices, FIFOs or folders are refused, by name, before any
//! work; images deleted since the rows were measured are rendered again.
mod common;

use common::cli::{Isr, Ran};
use common::temp_dir;
use isr::bench::files;
use std::path::Path;
use std::time::Duration;

/// The smallest bench: one scene, HISR's quick sweep, 32x32, one frame.
fn bench(dir: &Path, scene: &str) -> Isr {
    Isr::new("bench")
        .in_dir(dir)
        .args(["--scenes", scene, "--methods", "hisr", "--quick"])
        .args(["--width", "32", "--height", "32", "--rsm", "32"])
        .args(["--frames", "1", "--timing-frames", "1", "--out-dir", "b"])
        .hang_guard(Duration::from_secs(120))
}

fn keys(dir: &Path) -> Vec<String> {
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("b").join(files::RESULTS_JSON)).unwrap())
            .unwrap();
    json["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["key"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn a_journal_torn_inside_a_character_is_read_and_the_line_skipped() {
    let dir = temp_dir("bench-torn-utf8");
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    std::fs::copy(assets.join("cornell.gltf"), dir.join("café.gltf")).unwrap();
    bench(&dir, "café.gltf").succeeds();
    let all = keys(&dir);
    assert!(all.len() >= 2 && all.iter().all(|k| k.starts_with("café|")));
    let journal = dir.join("b").join(files::JOURNAL);
    let bytes = std::fs::read(&journal).unwrap();
    // Cut the last row inside its last `é` (0xC3 0xA9): invalid UTF-8.
    let cut = bytes.windows(2).rposition(|w| w == "é".as_bytes()).unwrap() + 1;
    let mut torn = bytes[..cut].to_vec();
    // And a line of bytes that are no row at all before it.
    let first_end = torn.iter().position(|&b| b == b'\n').unwrap() + 1;
    torn.splice(
        first_end..first_end,
        b"\xff\xfe not a row\n".iter().copied(),
    );
    std::fs::write(&journal, &torn).unwrap();
    let ran = bench(&dir, "café.gltf").succeeds();
    assert!(
        ran.stderr.contains(&format!("{} line 2", files::JOURNAL))
            && ran.stderr.contains("not valid UTF-8"),
        "the bad lines are not reported:\n{}",
        ran.stderr
    );
    let n = all.len() + 1;
    assert!(
        ran.stderr.contains(&format!("{} line {n}", files::JOURNAL)),
        "the torn last line is not reported:\n{}",
        ran.stderr
    );
    // The torn row was measured again; every row is there once.
    assert_eq!(keys(&dir), all);
    // A third run finds a journal it can read whole but for the same lines.
    let ran = bench(&dir, "café.gltf").succeeds();
    assert_eq!(keys(&dir), all, "{}", ran.stderr);
}

/// Expects `ran` to be refused before any work, naming `name`, and returns
/// the message.
fn refused(ran: Ran, name: &str) -> String {
    let e = ran.clean_failure();
    assert!(
        e.contains(name) && e.contains("not a regular file"),
        "the message does not name {name}:\n{e}"
    );
    e
}

#[cfg(unix)]
#[test]
fn special_files_in_the_bench_folder_are_refused_by_name_before_work() {
    let dir = temp_dir("bench-special");
    let b = dir.join("b");
    std::fs::create_dir_all(&b).unwrap();
    std::os::unix::fs::symlink("/dev/null", b.join(files::JOURNAL)).unwrap();
    refused(bench(&dir, "cornell").run(), files::JOURNAL);
    std::fs::remove_file(b.join(files::JOURNAL)).unwrap();
    // A FIFO: opening it would wait for a writer for ever.
    let fifo = std::ffi::CString::new(b.join(files::JOURNAL).into_os_string().into_encoded_bytes())
        .unwrap();
    // SAFETY: a valid C string; mkfifo only creates a file.
    assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0);
    refused(bench(&dir, "cornell").run(), files::JOURNAL);
    std::fs::remove_file(b.join(files::JOURNAL)).unwrap();
    // Any other output: a chart, an image of the gallery.
    std::os::unix::fs::symlink("/dev/null", b.join(files::RESULTS_CSV)).unwrap();
    refused(bench(&dir, "cornell").run(), files::RESULTS_CSV);
    std::fs::remove_file(b.join(files::RESULTS_CSV)).unwrap();
    let reference = files::images_dir(Path::new(""), "cornell").join(files::image("reference", ""));
    std::fs::create_dir_all(b.join(&reference)).unwrap();
    let e = bench(&dir, "cornell").fails();
    assert!(
        e.contains(reference.to_str().unwrap()) && e.contains("is a directory"),
        "{e}"
    );
    // Nothing was measured or written.
    let names: Vec<String> = std::fs::read_dir(&b)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [files::IMAGES],
        "written before the checks: {names:?}"
    );
}

/// The mean absolute difference of two images' bytes (RGBA8).
fn mean_difference(a: &Path, b: &Path) -> f64 {
    let (a, b) = (
        image::open(a).unwrap().to_rgba8(),
        image::open(b).unwrap().to_rgba8(),
    );
    assert_eq!(a.dimensions(), b.dimensions());
    let sum: u64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y) as u64)
        .sum();
    sum as f64 / a.as_raw().len() as f64
}

#[test]
fn deleted_images_are_rendered_again_and_the_rows_kept() {
    let dir = temp_dir("bench-images");
    let b = dir.join("b");
    bench(&dir, "cornell").succeeds();
    let rows = std::fs::read(b.join(files::JOURNAL)).unwrap();
    std::fs::copy(b.join(files::GALLERY), dir.join("gallery-first.png")).unwrap();
    let images = [
        files::image("reference", ""),
        files::image("hisr", ""),
        files::error_map("hisr", ""),
    ];
    std::fs::remove_dir_all(b.join(files::IMAGES)).unwrap();
    let ran = bench(&dir, "cornell").succeeds();
    for name in images {
        let path = files::images_dir(&b, "cornell").join(name);
        image::open(&path).unwrap_or_else(|e| panic!("{}: {e}\n{}", path.display(), ran.stderr));
    }
    // The rows were not measured again: the journal is as it was.
    assert_eq!(std::fs::read(b.join(files::JOURNAL)).unwrap(), rows);
    // The gallery shows the images again (blank tiles differ by far more).
    let d = mean_difference(&b.join(files::GALLERY), &dir.join("gallery-first.png"));
    assert!(d < 0.5, "the gallery differs from the first run's by {d}");
    // One image missing: only it is missing, and it comes back.
    let error_map = files::images_dir(&b, "cornell").join(files::error_map("hisr", ""));
    std::fs::remove_file(&error_map).unwrap();
    bench(&dir, "cornell").succeeds();
    assert!(error_map.is_file());
    assert_eq!(std::fs::read(b.join(files::JOURNAL)).unwrap(), rows);
}
