//! The house rules a reader of the code relies on, held as tests (no GPU,
//! milliseconds): no Rust file in `src/` or `tests/` over 600 lines, so
//! that a file stays one concern a reader can hold (split by concern, not
//! at line 600); and no ignored test in `tests/`, so that every test runs
//! with the suite (a measurement that only prints a table is an example or
//! a bench, not a test).

use std::path::{Path, PathBuf};

/// The most lines a `.rs` file in `src/` or `tests/` may have.
const MAX_LINES: usize = 600;

/// Every `.rs` file under `dir`, in a stable order.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = vec![];
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
    out
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn no_rust_file_in_src_or_tests_is_over_600_lines() {
    let mut long = vec![];
    for dir in ["src", "tests"] {
        for f in rust_files(&root().join(dir)) {
            let lines = std::fs::read_to_string(&f).unwrap().lines().count();
            if lines > MAX_LINES {
                let name = f.strip_prefix(root()).unwrap().display().to_string();
                long.push(format!("{name}: {lines} lines"));
            }
        }
    }
    assert!(
        long.is_empty(),
        "over {MAX_LINES} lines (split by concern):\n{}",
        long.join("\n")
    );
}

#[test]
fn no_test_is_ignored() {
    // Spelled in two pieces so that this file does not find itself.
    let attribute = concat!("#[", "ignore");
    let mut ignored = vec![];
    for f in rust_files(&root().join("tests")) {
        let text = std::fs::read_to_string(&f).unwrap();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim_start();
            let conditional = line.starts_with("#[cfg_attr") && line.contains("ignore");
            if line.starts_with(attribute) || conditional {
                let name = f.strip_prefix(root()).unwrap().display().to_string();
                ignored.push(format!("{name}:{}: {line}", i + 1));
            }
        }
    }
    assert!(
        ignored.is_empty(),
        "ignored tests (make a measurement an example or a bench):\n{}",
        ignored.join("\n")
    );
}
