//! `isr bench`: the quick sweep (the CI smoke test) writes every output with
//! finite numbers and resumes from its journal; bad input is a clear error.

mod common;

use common::cli::{Isr, Ran};
use common::temp_dir;
use std::path::Path;

fn bench(args: &[&str]) -> Ran {
    Isr::new("bench").args(args).run()
}

/// Every number anywhere in the JSON value.
fn numbers(v: &serde_json::Value, out: &mut Vec<f64>) {
    match v {
        serde_json::Value::Number(n) => out.push(n.as_f64().unwrap()),
        serde_json::Value::Array(a) => a.iter().for_each(|x| numbers(x, out)),
        serde_json::Value::Object(o) => o.values().for_each(|x| numbers(x, out)),
        _ => {}
    }
}

fn lines(p: &Path) -> usize {
    std::fs::read_to_string(p).unwrap().lines().count()
}

#[test]
fn quick_bench_writes_every_output_with_finite_numbers_and_resumes() {
    let dir = temp_dir("bench-quick");
    let d = dir.to_str().unwrap();
    Isr::new("bench")
        .args(["--quick", "--out-dir", d])
        .succeeds();
    for f in [
        "results.json",
        "results.csv",
        "speed_vs_error.svg",
        "speed_vs_error.png",
        "flicker.svg",
        "flicker.png",
        "passes.svg",
        "passes.png",
        "gallery.png",
        "report.md",
    ] {
        let p = dir.join(f);
        assert!(
            std::fs::metadata(&p).is_ok_and(|m| m.len() > 0),
            "{f} missing"
        );
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    let rows = json["rows"].as_array().unwrap();
    // Two scenes, each: the reference and 14 sweep points of 7 methods (two
    // VPL counts for each of five regular methods, two ISR bases, two taus).
    assert_eq!(rows.len(), 2 * 15);
    let mut all = vec![];
    numbers(&json, &mut all);
    assert!(all.iter().all(|v| v.is_finite()));
    for r in rows {
        for k in ["indirect_ms", "rel_rmse_indirect", "rel_rmse_final", "flip"] {
            assert!(r[k].as_f64().is_some_and(f64::is_finite), "{k} in {r}");
        }
        // Every scene is animated and three frames are compared.
        if r["method"] != "reference" {
            assert!(r["flicker"].as_f64().is_some(), "flicker in {r}");
        }
    }
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    assert_eq!(csv.lines().count(), rows.len() + 1);
    for cell in csv.lines().skip(1).flat_map(|l| l.split(',')) {
        if let Ok(v) = cell.parse::<f64>() {
            assert!(v.is_finite());
        }
    }
    // A second run finds every row in the journal and renders nothing.
    let journal = dir.join("rows.jsonl");
    let before = lines(&journal);
    Isr::new("bench")
        .args(["--quick", "--out-dir", d])
        .succeeds();
    assert_eq!(lines(&journal), before);
    // An interrupted run: drop the last rows; the rerun renders only those.
    let text = std::fs::read_to_string(&journal).unwrap();
    let kept: Vec<&str> = text.lines().take(before - 3).collect();
    std::fs::write(&journal, kept.join("\n") + "\n").unwrap();
    Isr::new("bench")
        .args(["--quick", "--out-dir", d, "--scenes", "slats"])
        .succeeds();
    assert_eq!(lines(&journal), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_names_list_the_valid_ones() {
    let dir = temp_dir("bench-bad");
    let d = dir.to_str().unwrap();
    let fails =
        |args: &[&str]| bench(&[&["--quick", "--out-dir", d], args].concat()).clean_failure();
    let err = fails(&["--scenes", "atrium"]);
    assert!(
        err.contains("unknown scene 'atrium'") && err.contains("cornell, fine, hall"),
        "{err}"
    );
    let err = fails(&["--methods", "hisr,magic"]);
    assert!(
        err.contains("magic") && err.contains("multires-gather"),
        "{err}"
    );
    let err = fails(&["--methods", "reference"]);
    assert!(
        err.contains("has no sweep") && err.contains("hisr"),
        "{err}"
    );
    // Nothing was rendered, and no panic (exit status 1, `clean_failure`).
    let err = fails(&["--rsm", "100"]);
    assert!(err.contains("power of two"), "{err}");
    assert!(!dir.join("rows.jsonl").exists());
}
