//! `report.md`'s table of the passes every method renders (the RSM, the
//! G-buffer, the direct light's shadow map and its shading, the composite):
//! what a frame costs before any indirect light, per scene, so that a
//! method's indirect time reads against it. The shadow map is drawn apart
//! from the RSM (docs/algorithm.md section 2.2) and shows its own cost here.

use super::rows::Row;
use super::Plan;

/// The median of `v` (not empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The passes timed in every row of `rows` (those of the first, by name),
/// with the median over the rows of each one's time (ms); empty without
/// rows.
fn shared(rows: &[&Row]) -> Vec<(String, f64)> {
    let Some(first) = rows.first() else {
        return vec![];
    };
    first
        .passes
        .keys()
        .filter(|p| rows.iter().all(|r| r.passes.contains_key(*p)))
        .map(|p| {
            let ms = median(rows.iter().map(|r| r.passes[p]).collect());
            (p.clone(), ms)
        })
        .collect()
}

/// The table, over the rows without indirect visibility (the grid is a
/// method's choice), a column per shared pass; empty when no row timed one.
pub fn table(plan: &Plan, rows: &[Row]) -> String {
    let per_scene: Vec<(&str, Vec<(String, f64)>)> = plan
        .scenes
        .iter()
        .map(|s| {
            let of: Vec<&Row> = rows
                .iter()
                .filter(|r| r.scene == s.name && r.visibility == "none" && !r.passes.is_empty())
                .collect();
            (s.name.as_str(), shared(&of))
        })
        .filter(|(_, p)| !p.is_empty())
        .collect();
    let Some((_, first)) = per_scene.first() else {
        return String::new();
    };
    let names: Vec<&str> = first.iter().map(|(n, _)| n.as_str()).collect();
    let b = &plan.base;
    let mut md = format!(
        "\n## Passes every method shares\n\nMedian GPU time (ms) of each pass that every row of a scene \
renders, over the rows without indirect visibility: RSM {r}x{r}, the direct light's shadow map \
{s}x{s} (`--shadow`, drawn apart from the RSM: docs/algorithm.md section 2.2), at {w}x{h}.\n\n| scene |",
        r = b.rsm_resolution,
        s = b.shadow_size(),
        w = b.width,
        h = b.height
    );
    for n in &names {
        md += &format!(" {n} |");
    }
    md += "\n| --- |";
    md += &" ---: |".repeat(names.len());
    md += "\n";
    for (scene, passes) in &per_scene {
        md += &format!("| {scene} |");
        for n in &names {
            md += &match passes.iter().find(|(p, _)| p == n) {
                Some((_, ms)) => format!(" {ms:.1} |"),
                None => " - |".into(),
            };
        }
        md += "\n";
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(passes: &[(&str, f64)]) -> Row {
        Row {
            passes: passes.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
            ..crate::bench::rows::tests_support::row("k")
        }
    }

    #[test]
    fn only_passes_every_row_renders_with_their_median() {
        let rows = [
            row(&[("shadow", 1.0), ("gather", 9.0)]),
            row(&[("shadow", 3.0)]),
            row(&[("shadow", 2.0), ("gather", 1.0)]),
        ];
        let refs: Vec<&Row> = rows.iter().collect();
        assert_eq!(shared(&refs), vec![("shadow".to_string(), 2.0)]);
        assert_eq!(median(vec![4.0, 1.0]), 2.5);
        assert!(shared(&[]).is_empty());
    }
}
