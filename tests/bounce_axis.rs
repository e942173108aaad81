//! `isr bench`'s bounces axis (docs/algorithm.md section 6.6, "Bounces"): a
//! full run of one bounce traces the truth of every bounce once per frame
//! and measures the subject with 1, 2, 3 and every bounce against it.

mod common;

use common::cli::Isr;
use common::temp_dir;
use isr::bench::files;

/// A full run (not `--quick`, which leaves the axis out) of the box, small:
/// the truth of every bounce is traced once, not the truth of one beside
/// it; the subject's axis rows fall in error against it as they render more
/// bounces; the report says what the rule picks; a second run measures
/// nothing again.
#[test]
fn the_bounces_axis_measures_the_subject_against_the_truth_of_every_bounce() {
    let dir = temp_dir("bench-bounce-axis");
    let d = dir.to_str().unwrap();
    let run = || {
        Isr::new("bench")
            .args(["--scenes", "cornell", "--methods", "hisr"])
            .args(["--width", "32", "--height", "32", "--rsm", "32"])
            .args([
                "--frames",
                "1",
                "--timing-frames",
                "1",
                "--truth-noise",
                "0.1",
            ])
            .args(["--visibility", "voxels", "--out-dir", d])
            .succeeds();
    };
    run();
    let truths = files::truth_dir(&dir, "cornell");
    assert!(truths.join("frame-0-bounces-inf.exr").is_file());
    assert!(!truths.join("frame-0.exr").exists(), "traced twice");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join(files::RESULTS_JSON)).unwrap())
            .unwrap();
    let axis: Vec<isr::bench::rows::Row> =
        serde_json::from_value(json["bounce_axis"].clone()).unwrap();
    let bounces: Vec<&str> = axis.iter().map(|r| r.bounces.as_str()).collect();
    assert_eq!(bounces, ["1", "2", "3", "inf"]);
    // The other rows stay of one bounce.
    let rows = json["rows"].as_array().unwrap();
    assert!(rows.iter().all(|r| r["bounces"] == "1"));
    let every = |r: &isr::bench::rows::Row| r.truth.rel_rmse_indirect.unwrap();
    for r in &axis {
        println!(
            "{} bounces: {:.4} against every bounce, extra light {:?}, shares {:?}",
            r.bounces,
            every(r),
            r.truth.extra_light,
            r.truth.shares
        );
        assert!(
            r.method == "hisr" && r.visibility.starts_with("voxels"),
            "{r:?}"
        );
        assert!(every(r).is_finite() && r.indirect_ms.is_some(), "{r:?}");
        // The box's first bounce is about half its light (section 5.4,
        // "Bounces"; 59% here): between 40% and 70%, summing to 1.
        let shares = r.truth.shares.clone().unwrap();
        assert!((0.4..0.7).contains(&shares[0]), "{shares:?}");
        assert!(
            (shares.iter().sum::<f64>() - 1.0).abs() < 1e-6,
            "{shares:?}"
        );
        // Extra light for 2 bounces and more: 0.68-0.82 of the truth's
        // here. Between a half and 1.5 tells bounces that add light of the
        // truth's order from none added (0) or twice it.
        match r.bounces.as_str() {
            "1" => assert!(r.truth.extra_light.is_none()),
            _ => {
                let x = r.truth.extra_light.unwrap();
                assert!((0.5..1.5).contains(&x), "{} bounces: {x}", r.bounces);
            }
        }
    }
    // Against the truth of every bounce, one bounce misses about half the
    // light: 0.42 against 0.16 with every bounce here; under 0.75x
    // tells rendered bounces from none.
    assert!(every(&axis[3]) < 0.75 * every(&axis[0]), "{axis:?}");
    assert_eq!(axis[3].truth.same_bounces, axis[3].truth.rel_rmse_indirect);
    let report = std::fs::read_to_string(dir.join(files::REPORT)).unwrap();
    assert!(report.contains("## Bounces") && report.contains("The rule picks `--bounces "));
    let journal = std::fs::read_to_string(dir.join(files::JOURNAL)).unwrap();
    run();
    assert_eq!(
        std::fs::read_to_string(dir.join(files::JOURNAL)).unwrap(),
        journal
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
