//! The bench's visibility axis (issue 25 part 3; docs/algorithm.md section
//! 6.7): `isr bench --visibility none,voxels` renders every method without
//! indirect visibility, and every method that reads it
//! (`Descriptor::reads_visibility`) again with each further entry. A run is
//! one pass per visibility ([`Plan::passes`]): each pass has its own dense
//! reference, rendered with the same visibility, which its rows' errors
//! against "the reference" are against; every pass shares the scene's one
//! path-traced truth per frame.

use super::rows::Row;
use super::Plan;
use crate::settings::{Method, RenderSettings};
use crate::visibility::{Visibility, VISIBILITY};
use crate::voxel_grid::{GRID, SUBCELLS};
use anyhow::{bail, Result};

/// What `isr bench --visibility` takes; `exact` is refused by [`parse`].
const NAMES: &[(&str, Visibility)] = &[("none", Visibility::None), ("voxels", Visibility::Voxels)];

/// The visibilities of `--visibility`'s list, in its order, each once.
/// Empty: [`default`]. `exact` is refused: it is CPU minutes per frame.
pub fn parse(list: &[String], quick: bool) -> Result<Vec<Visibility>> {
    if list.is_empty() {
        return Ok(default(quick));
    }
    let mut out = vec![];
    for entry in list {
        let name = entry.trim();
        if name == "exact" {
            bail!(
                "--visibility exact is not a bench visibility: one CPU ray per pixel and VPL is \
                 minutes per frame. Render it with `isr render --method reference --visibility \
                 exact`; the bench already uses it once per scene, for the model floor \
                 (truth_floor) of its dense reference at the middle frame. Choose from: none, voxels"
            );
        }
        let Some(&(_, v)) = NAMES.iter().find(|(n, _)| *n == name) else {
            bail!("unknown --visibility '{entry}'; choose from: none, voxels (comma-separated)");
        };
        if !out.contains(&v) {
            out.push(v);
        }
    }
    Ok(out)
}

/// The default list: a full run with and without the grid (its extra cost,
/// the grid's rows, is small beside the truth's); `--quick`, the CI smoke
/// test, without it only.
pub fn default(quick: bool) -> Vec<Visibility> {
    match quick {
        true => vec![Visibility::None],
        false => vec![Visibility::None, Visibility::Voxels],
    }
}

/// `s` with visibility `v`, set explicitly whatever the default.
pub fn with(s: &RenderSettings, v: Visibility) -> RenderSettings {
    let mut s = s.clone();
    VISIBILITY.set(&mut s, v);
    s
}

/// The visibilities of `rows` (`Row::visibility`), in first appearance.
pub fn visibilities(rows: &[Row]) -> Vec<&str> {
    let mut out: Vec<&str> = vec![];
    for r in rows {
        if !out.contains(&r.visibility.as_str()) {
            out.push(&r.visibility);
        }
    }
    out
}

/// Whether `method` renders differently with indirect visibility.
pub fn reads(method: Method) -> bool {
    crate::methods::find(method).is_ok_and(|d| d.reads_visibility())
}

/// The visibility of rows rendered with `s`, as rows and tables show it:
/// `none`, or `voxels N sub S` with the grid's side and sub-cells (`voxels
/// N` for the plain grid, as rows were labelled before there were
/// sub-cells, so that a journal's older rows keep what they measured).
pub fn label(s: &RenderSettings) -> String {
    match VISIBILITY.get(s) {
        Visibility::None => "none".into(),
        Visibility::Voxels => match SUBCELLS.get(s) {
            1 => format!("voxels {}", GRID.get(s)),
            sub => format!("voxels {} sub {sub}", GRID.get(s)),
        },
        Visibility::Exact => "exact".into(),
    }
}

/// How a method's name is told apart in charts and tables: `hisr`, or
/// `hisr + voxels 64` for a row of visibility `visibility` (a row's label).
pub fn series_name(method: &str, visibility: &str) -> String {
    match visibility {
        "" | "none" => method.to_string(),
        v => format!("{method} + {v}"),
    }
}

impl Plan {
    /// The visibility this plan's rows render with (a pass's; the run's
    /// own plan: `none`).
    pub fn visibility(&self) -> Visibility {
        VISIBILITY.get(&self.base)
    }

    /// [`label`] of this plan's rows.
    pub fn visibility_label(&self) -> String {
        label(&self.base)
    }

    /// What a gallery image's name gets for this plan's visibility:
    /// `hisr.png`, `hisr-voxels.png`.
    pub fn image_suffix(&self) -> &'static str {
        match self.visibility() {
            Visibility::None => "",
            Visibility::Voxels => "-voxels",
            Visibility::Exact => "-exact",
        }
    }

    /// The passes of a run (or of one scene's plan, `for_scene`), in report
    /// order: first `none`, with the dense reference that gives the model
    /// error and every method that reads no visibility (every method where
    /// the list has `none`); then each further visibility of the list, with
    /// its own dense reference and the methods that read it (a pass with
    /// no such method is left out).
    pub fn passes(&self) -> Vec<Plan> {
        let pass = |v: Visibility, methods: Vec<Method>| Plan {
            base: with(&self.base, v),
            methods,
            visibilities: vec![v],
            ..self.clone()
        };
        let all_none = self.visibilities.contains(&Visibility::None);
        let none: Vec<Method> = self
            .methods
            .iter()
            .copied()
            .filter(|&m| all_none || !reads(m))
            .collect();
        let mut out = vec![pass(Visibility::None, none)];
        for &v in self.visibilities.iter().filter(|&&v| v != Visibility::None) {
            let readers: Vec<Method> = self.methods.iter().copied().filter(|&m| reads(m)).collect();
            if !readers.is_empty() {
                out.push(pass(v, readers));
            }
        }
        out
    }
}

/// `report.md`'s table of the axis: per scene, the dense reference and each
/// method at its default point without visibility and with each further
/// visibility of the run: error against the truth, against the dense
/// reference (each row's own, with its visibility), indirect time and its
/// ratio, flicker. Empty when the rows have one visibility.
pub fn report_table(plan: &Plan, rows: &[Row]) -> String {
    let mut md = String::new();
    for other in visibilities(rows) {
        if matches!(other, "" | "none") {
            continue;
        }
        let pairs: Vec<(&Row, &Row)> = plan
            .scenes
            .iter()
            .flat_map(|s| pairs(rows, &s.name, other))
            .collect();
        if pairs.is_empty() {
            continue;
        }
        md += &format!(
            "\n## Indirect visibility: none against {other}\n\nEach method that reads indirect \
visibility at its default point (the dense reference: its one point), without and with {other}: relative \
RMSE of the indirect image against the path-traced truth (over its mask; the same truth for both), and \
against the dense reference with the row's visibility (the reference's own: 0); median indirect ms and \
the cost of the visibility (with over without); flicker (section 6.3), on scenes that move.\n\n\
| scene | method | setting | RMSE truth | + {other} | RMSE reference | + {other} | indirect ms | + {other} \
| cost | flicker | + {other} |\n| --- | --- | --- |{}\n",
            " ---: |".repeat(9)
        );
        let f4 = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.4}"));
        let f1 = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.1}"));
        for (a, b) in pairs {
            let cost = a.indirect_ms.zip(b.indirect_ms).map(|(a, b)| b / a);
            md += &format!(
                "| {} | {} | {} | {} | {} | {:.4} | {:.4} | {} | {} | {} | {} | {} |\n",
                a.scene,
                a.method,
                a.label,
                f4(a.truth.rel_rmse_indirect),
                f4(b.truth.rel_rmse_indirect),
                a.rel_rmse_indirect,
                b.rel_rmse_indirect,
                f1(a.indirect_ms),
                f1(b.indirect_ms),
                cost.map_or("-".into(), |c| format!("{c:.2}x")),
                f4(a.flicker),
                f4(b.flicker),
            );
        }
    }
    md
}

/// The default rows of `scene` without visibility that have a row of the
/// same method and setting with visibility `other`, each with it; the
/// reference first.
fn pairs<'a>(rows: &'a [Row], scene: &str, other: &str) -> Vec<(&'a Row, &'a Row)> {
    let without = rows.iter().filter(|r| {
        r.scene == scene && r.is_default && matches!(r.visibility.as_str(), "" | "none")
    });
    let mut out: Vec<(&Row, &Row)> = without
        .filter_map(|a| {
            let b = rows.iter().find(|b| {
                b.scene == a.scene
                    && b.method == a.method
                    && b.label == a.label
                    && b.visibility == other
            })?;
            Some((a, b))
        })
        .collect();
    out.sort_by_key(|(a, _)| a.method != crate::methods::REFERENCE.name());
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::BenchArgs;

    fn plan(visibility: &[&str], methods: &[&str]) -> Result<Plan> {
        BenchArgs {
            scenes: vec!["cornell".into()],
            methods: methods.iter().map(|m| m.to_string()).collect(),
            visibility: visibility.iter().map(|m| m.to_string()).collect(),
            ..Default::default()
        }
        .plan()
    }

    #[test]
    fn readers_get_a_pass_per_visibility_and_the_others_one_without() {
        let p = plan(&["none", "voxels"], &["hisr", "lpv"]).unwrap();
        let passes = p.passes();
        let names = |q: &Plan| -> Vec<&str> { q.methods.iter().map(|m| m.name()).collect() };
        assert_eq!(passes.len(), 2);
        assert_eq!(names(&passes[0]), ["hisr", "lpv"]);
        assert_eq!(passes[0].visibility_label(), "none");
        assert_eq!(names(&passes[1]), ["hisr"]);
        assert_eq!(passes[1].visibility_label(), "voxels 64 sub 4");
        // `none` rows' keys are those of a run before the axis; the grid's
        // carry it, as `--visibility voxels` runs' did.
        let key = |q: &Plan| q.key("cornell", "hisr", "tau 0.2, depth 7");
        assert_eq!(key(&passes[0]), key(&p));
        assert!(key(&passes[1]).ends_with("|voxels 64 sub 4"));
        // The plain grid keeps the label (and key) it had before sub-cells.
        let mut plain = passes[1].base.clone();
        SUBCELLS.set(&mut plain, 1);
        assert_eq!(label(&plain), "voxels 64");
        // Without `none` in the list, the methods that read no visibility
        // still render once without it, beside the model error's reference.
        let p = plan(&["voxels"], &["hisr", "lpv"]).unwrap();
        let passes = p.passes();
        assert_eq!(names(&passes[0]), ["lpv"]);
        assert_eq!(names(&passes[1]), ["hisr"]);
        // No method reads it: one pass.
        assert_eq!(
            plan(&["none", "voxels"], &["lpv"]).unwrap().passes().len(),
            1
        );
    }

    #[test]
    fn the_report_pairs_each_default_point_without_and_with_the_grid() {
        let row = |method: &str, visibility: &str, truth: f64, ms: f64| {
            let mut r = crate::bench::rows::tests_support::row(method);
            r.scene = "cornell".into();
            r.method = method.into();
            r.visibility = visibility.into();
            r.truth.rel_rmse_indirect = Some(truth);
            r.indirect_ms = Some(ms);
            r
        };
        let mut lpv = row("lpv", "none", 0.5, 3.0);
        lpv.label = "32^3".into();
        let mut other = row("hisr", "none", 0.2, 1.0);
        other.is_default = false;
        let rows = [
            row("reference", "none", 0.16, 100.0),
            row("hisr", "none", 0.15, 10.0),
            other,
            lpv,
            row("hisr", "voxels 64", 0.04, 40.0),
            row("reference", "voxels 64", 0.03, 500.0),
        ];
        let p = plan(&["none", "voxels"], &["hisr", "lpv"]).unwrap();
        let md = report_table(&p, &rows);
        assert!(
            md.contains("## Indirect visibility: none against voxels 64"),
            "{md}"
        );
        let lines: Vec<&str> = md.lines().filter(|l| l.starts_with("| cornell")).collect();
        // The reference first; LPV has no row with the grid, so no line.
        assert_eq!(lines.len(), 2, "{md}");
        assert!(
            lines[0].starts_with("| cornell | reference |"),
            "{}",
            lines[0]
        );
        assert!(lines[0].contains("| 0.1600 | 0.0300 |") && lines[0].contains("| 5.00x |"));
        assert!(lines[1].contains("| 0.1500 | 0.0400 |") && lines[1].contains("| 4.00x |"));
        // One visibility: no table.
        assert!(report_table(&p, &rows[..4]).is_empty());
    }

    #[test]
    fn the_list_is_checked_and_exact_is_refused_with_why() {
        let e = plan(&["exact"], &[]).unwrap_err().to_string();
        assert!(
            e.contains("minutes per frame") && e.contains("isr render --method reference"),
            "{e}"
        );
        let e = plan(&["none", "rays"], &[]).unwrap_err().to_string();
        assert!(e.contains("'rays'") && e.contains("none, voxels"), "{e}");
        let p = plan(&["voxels", "none", "voxels"], &[]).unwrap();
        assert_eq!(p.visibilities, [Visibility::Voxels, Visibility::None]);
        assert_eq!(plan(&[], &[]).unwrap().visibilities, default(false));
        assert_eq!(default(true), [Visibility::None]);
    }
}
