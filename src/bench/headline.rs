//! The headline of a bench run: its tables (every method at its default,
//! its indirect time and its error against the path-traced truth, per scene
//! and visibility), each method's best balance, and the block between
//! [`BEGIN`] and [`END`] that `isr bench --publish` (`publish`) copies into
//! the README.

use super::rows::Row;
use super::visibility::{series_name, visibilities};
use super::{Outcome, Plan};

/// The markers of the headline block in README.md and docs/results.md.
pub const BEGIN: &str = "<!-- results:begin -->";
pub const END: &str = "<!-- results:end -->";

/// A setting is within the best balance's reach when its error against the
/// truth on the bench scenes is at most this many times the lowest any
/// setting of the method reaches (see [`best_balance`]).
pub const BALANCE: f64 = 1.25;

/// A method's setting across the scenes of a run: its visibility and label.
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    pub visibility: String,
    pub label: String,
    /// Its error on the bench scenes: the mean, over the scenes, of its error
    /// against the truth relative to the lowest any setting of the method
    /// reaches on that scene (1: the lowest everywhere).
    pub relative_error: f64,
    /// Its indirect time summed over the scenes (ms).
    pub total_ms: f64,
}

/// Every setting of `method` in `rows` with an error against the truth and
/// a time on every scene of the run, with its relative error and time.
pub fn settings(rows: &[Row], method: &str) -> Vec<Setting> {
    let mut scenes: Vec<&str> = vec![];
    for r in rows {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    let of = |r: &&Row| r.method == method && r.truth.rel_rmse_indirect.is_some();
    let lowest = |scene: &str| {
        rows.iter()
            .filter(of)
            .filter(|r| r.scene == scene)
            .filter_map(|r| r.truth.rel_rmse_indirect)
            .fold(f64::INFINITY, f64::min)
    };
    let lowest: Vec<f64> = scenes.iter().map(|s| lowest(s)).collect();
    let mut keys: Vec<(&str, &str)> = vec![];
    for r in rows.iter().filter(of) {
        if !keys.contains(&(r.visibility.as_str(), r.label.as_str())) {
            keys.push((&r.visibility, &r.label));
        }
    }
    keys.into_iter()
        .filter_map(|(v, l)| {
            let (mut ratio, mut ms) = (0.0, 0.0);
            for (s, low) in scenes.iter().zip(&lowest) {
                let r = rows
                    .iter()
                    .filter(of)
                    .find(|r| r.scene == *s && r.visibility == v && r.label == l)?;
                ratio += r.truth.rel_rmse_indirect? / low.max(1e-12);
                ms += r.indirect_ms?;
            }
            Some(Setting {
                visibility: v.into(),
                label: l.into(),
                relative_error: ratio / scenes.len() as f64,
                total_ms: ms,
            })
        })
        .collect()
}

/// A method's best balance in `rows`: the cheapest of its settings whose
/// error on the bench scenes is within [`BALANCE`] of the lowest
/// ([`settings`]). The one definition of a default: the defaults `isr`
/// ships are the subject's best balance in docs/results.md.
pub fn best_balance(rows: &[Row], method: &str) -> Option<Setting> {
    settings(rows, method)
        .into_iter()
        .filter(|s| s.relative_error <= BALANCE)
        .min_by(|a, b| a.total_ms.total_cmp(&b.total_ms))
}

/// The scenes of `rows`, in first appearance.
fn scenes(rows: &[Row]) -> Vec<&str> {
    let mut out: Vec<&str> = vec![];
    for r in rows {
        if !out.contains(&r.scene.as_str()) {
            out.push(&r.scene);
        }
    }
    out
}

/// "1,234 ms" above 1000, "12 ms" above 10, "9.2 ms" below.
pub(super) fn ms(v: f64) -> String {
    match v {
        v if v >= 1000.0 => {
            let n = v.round() as u64;
            format!("{},{:03} ms", n / 1000, n % 1000)
        }
        v if v >= 10.0 => format!("{v:.0} ms"),
        v => format!("{v:.1} ms"),
    }
}

/// The headline tables: per visibility of the run, every method at its
/// default on every scene, its indirect time and its error against the
/// truth; with the dense reference's floor (exact visibility) under the
/// first. What README.md shows between the markers.
pub fn headline(plan: &Plan, o: &Outcome) -> String {
    let scenes = scenes(&o.rows);
    let b = &plan.base;
    let mut md = format!(
        "{BEGIN}\nFrom one run of `{}` on {} ({}), {}: the bench scenes at {}x{}, RSM {}, {} animation \
frames. Each cell: indirect time (median, ms), then the relative RMSE of the indirect image against the \
path-traced truth over the pixels away from geometric and shadow edges, mean over the frames (the truth's \
own noise included). Full tables, charts and each method's best balance: \
[docs/results.md](docs/results.md).\n",
        o.command,
        o.device,
        o.driver,
        o.date,
        b.width,
        b.height,
        b.rsm_resolution,
        plan.frames
    );
    for v in visibilities(&o.rows) {
        md += &match v {
            "none" | "" => "\nWithout indirect visibility (the paper's model):\n\n".to_string(),
            v => format!("\nWith `--visibility {v}`:\n\n"),
        };
        md += "| method (default) |";
        for s in &scenes {
            md += &format!(" `{s}` |");
        }
        md += "\n| --- |";
        md += &" ---: |".repeat(scenes.len());
        md += "\n";
        let mut methods: Vec<(&str, &str)> = vec![];
        for r in o.rows.iter().filter(|r| r.visibility == v && r.is_default) {
            if !methods.iter().any(|(m, _)| *m == r.method) {
                methods.push((&r.method, &r.label));
            }
        }
        for (m, label) in methods {
            md += &format!("| `{m}` ({label}) |");
            for s in &scenes {
                let r = o
                    .rows
                    .iter()
                    .find(|r| r.scene == *s && r.method == m && r.visibility == v && r.is_default);
                md += &match r {
                    Some(r) => format!(
                        " {}, {} |",
                        r.indirect_ms.map_or("-".into(), ms),
                        r.truth
                            .rel_rmse_indirect
                            .map_or("-".into(), |e| format!("{e:.3}"))
                    ),
                    None => " - |".into(),
                };
            }
            md += "\n";
        }
        let reference = crate::methods::REFERENCE.name();
        let floor: Vec<Option<f64>> = scenes
            .iter()
            .map(|s| {
                o.rows
                    .iter()
                    .find(|r| r.scene == *s && r.method == reference && r.visibility == v)
                    .and_then(|r| r.truth.floor)
            })
            .collect();
        if floor.iter().any(|f| f.is_some()) {
            md += &format!("| `{reference} --visibility exact` (the model's floor) |");
            for f in floor {
                md += &format!(" {} |", f.map_or("-".into(), |f| format!("{f:.3}")));
            }
            md += "\n";
        }
    }
    md += &super::bounce_axis::headline(&o.bounce_rows);
    md += END;
    md += "\n";
    md
}

/// The best balance of every method with errors against the truth, and the
/// subject's settings around it: what the defaults are chosen by.
pub fn balance_section(o: &Outcome) -> String {
    let mut md = format!(
        "\n## Best balance\n\nA setting's error on the bench scenes is the mean, over the scenes, of its \
error against the truth relative to the lowest any setting of the method reaches there (with or without \
visibility). A method's best balance is its cheapest setting (indirect time summed over the scenes) whose \
error is within {BALANCE}x of the lowest. The defaults `isr` ships are the subject's \
(`{}`) best balance.\n\n| method | best balance | error (x the lowest) | indirect ms, summed |\n\
| --- | --- | ---: | ---: |\n",
        crate::methods::SUBJECT.name()
    );
    let mut methods: Vec<&str> = vec![];
    for r in &o.rows {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    for m in &methods {
        if let Some(b) = best_balance(&o.rows, m) {
            md += &format!(
                "| `{m}` | {} | {:.2} | {} |\n",
                series_name(&b.label, &b.visibility),
                b.relative_error,
                ms(b.total_ms)
            );
        }
    }
    let subject = crate::methods::SUBJECT.name();
    let mut all = settings(&o.rows, subject);
    if !all.is_empty() {
        all.sort_by(|a, b| a.total_ms.total_cmp(&b.total_ms));
        md += &format!(
            "\nEvery setting of `{subject}`, cheapest first:\n\n| setting | error (x the lowest) | \
indirect ms, summed |\n| --- | ---: | ---: |\n"
        );
        for s in all {
            md += &format!(
                "| {}{} | {:.2} | {} |\n",
                series_name(&s.label, &s.visibility),
                if s.relative_error <= BALANCE {
                    " (within)"
                } else {
                    ""
                },
                s.relative_error,
                ms(s.total_ms)
            );
        }
    }
    md
}

/// The headline block of `text` (between the markers, included).
pub fn block(text: &str) -> Option<&str> {
    let start = text.find(BEGIN)?;
    let end = text[start..].find(END)? + start + END.len();
    Some(&text[start..end])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(scene: &str, label: &str, visibility: &str, ms: f64, err: f64) -> Row {
        let mut r = super::super::rows::tests_support::row(scene);
        r.scene = scene.into();
        r.method = "m".into();
        r.label = label.into();
        r.visibility = visibility.into();
        r.indirect_ms = Some(ms);
        r.truth.rel_rmse_indirect = Some(err);
        r
    }

    #[test]
    fn the_best_balance_is_the_cheapest_within_reach_of_the_lowest_error() {
        let rows = vec![
            // a: the lowest error everywhere, the most expensive.
            row("s1", "a", "voxels", 100.0, 0.10),
            row("s2", "a", "voxels", 100.0, 0.20),
            // b: 1.2x and 1.25x the lowest: mean 1.225, within.
            row("s1", "b", "voxels", 50.0, 0.12),
            row("s2", "b", "voxels", 50.0, 0.25),
            // c: cheapest, 1.5x on one scene: mean 1.25, within, and cheaper.
            row("s1", "c", "none", 10.0, 0.10),
            row("s2", "c", "none", 10.0, 0.30),
            // d: cheaper still, past reach.
            row("s1", "d", "none", 1.0, 0.20),
            row("s2", "d", "none", 1.0, 0.40),
        ];
        let b = best_balance(&rows, "m").unwrap();
        assert_eq!((b.label.as_str(), b.visibility.as_str()), ("c", "none"));
        assert!((b.relative_error - 1.25).abs() < 1e-12);
        assert_eq!(b.total_ms, 20.0);
        // A setting missing a scene is not a candidate.
        let mut partial = rows.clone();
        partial.retain(|r| !(r.label == "c" && r.scene == "s2"));
        assert_eq!(best_balance(&partial, "m").unwrap().label, "b");
        assert!(best_balance(&rows, "other").is_none());
    }

    #[test]
    fn the_block_is_found_between_its_markers() {
        let text = format!("a\n{BEGIN}\nx | y\n{END}\nb");
        assert_eq!(block(&text), Some(&text[2..text.len() - 2]));
        assert_eq!(block("no markers"), None);
    }
}
