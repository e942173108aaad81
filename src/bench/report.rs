//! What a bench run writes from its rows: `results.json`, `results.csv`, the
//! charts, the gallery, and `report.md` with its tables and the ratios
//! (`ratios`), computed from the same rows.

use super::files::{self, Chart};
use super::ratios::{flicker_64_over_4096, fmt_value, ratios, regular, with_visibility, Ratio};
use super::rows;
use super::visibility::visibilities;
use super::{Outcome, Plan};
use anyhow::Result;
use serde_json::json;

/// `report.md`'s table of flicker with 64 over 4096 regular VPLs, per
/// scene and method: low-passed, and per pixel in brackets; of the rows
/// without visibility (what the measure was made to tell apart).
fn flicker_table(plan: &Plan, o: &Outcome) -> String {
    let rows = with_visibility(&o.rows, "none");
    let methods: Vec<&str> = regular()
        .into_iter()
        .filter(|m| {
            plan.scenes
                .iter()
                .any(|s| flicker_64_over_4096(&rows, &s.name, m).is_some())
        })
        .collect();
    if methods.is_empty() {
        return String::new();
    }
    let mut md = "\n## Flicker: 64 against 4096 regular VPLs\n\nFlicker (section 6.3) with 64 VPLs over \
flicker with 4096, per scene and method: low-passed (the measure), and in brackets per pixel (the measure \
before the low-pass, which the dense reference's own near-contact change dominates on `fine` and \
`slats`). Above 1: 64 VPLs flicker more.\n\n| scene |"
        .to_string();
    for m in &methods {
        md += &format!(" {m} |");
    }
    md += "\n| --- |";
    md += &" ---: |".repeat(methods.len());
    md += "\n";
    for s in &plan.scenes {
        md += &format!("| {} |", s.name);
        for m in &methods {
            md += &match flicker_64_over_4096(&rows, &s.name, m) {
                Some(((a, b), pixel)) => format!(
                    " {:.2} ({}) |",
                    a / b,
                    pixel.map_or("-".into(), |(c, d)| format!("{:.2}", c / d))
                ),
                None => " - |".into(),
            };
        }
        md += "\n";
    }
    md
}

fn cell<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map_or("-".into(), |v| v.to_string())
}

/// `report.md`: run facts, the headline tables, charts, best balances,
/// ratios and one table per scene; its images are at `images` (a folder
/// prefix: "" beside it, `results/` when published into docs/).
pub fn markdown(plan: &Plan, o: &Outcome, ratios: &[Ratio], images: &str) -> String {
    let b = &plan.base;
    let mut md = format!(
        "# isr bench\n\n`{}` on {}: device **{}**, driver {}. {}x{}, RSM {}, {} animation frames per scene \
(1/fps apart), {} timing frames at the first; times are medians of GPU timestamps (docs/algorithm.md \
section 6.2), errors means over frames against the dense reference of the same frame (section 6.1) \
and against {} (section 6.6; with `--bounces` the gathering methods render as many through the voxel grid's cells, section 5.9), flicker \
over the sequence (section 6.3), FLIP on the tone-mapped final image (section 6.4). Indirect \
visibility: {} (section 6.7; a row with it is held against the dense reference with it, and the one \
truth of each frame).{}\n\n",
        o.command,
        o.date,
        o.device,
        o.driver,
        b.width,
        b.height,
        b.rsm_resolution,
        plan.frames,
        plan.timing_frames,
        super::bounces::rows_truth_words(&o.rows),
        visibilities(&o.rows).join(", "),
        if plan.quick { " Quick run (smoke test)." } else { "" }
    );
    for chart in Chart::ALL {
        let alt = match chart {
            Chart::SpeedVsError => "speed against error",
            Chart::SpeedVsTruth => "speed against error from the truth",
            Chart::Flicker => "flicker",
            Chart::Passes => "per-pass times",
        };
        md += &format!("![{alt}]({images}{})\n\n", chart.svg());
    }
    md += &format!("![gallery]({images}{})\n\n", files::GALLERY);
    md += "## At each method's default, against the truth\n\n";
    md += &super::headline::headline(plan, o);
    md += &super::headline::balance_section(o);
    md += "\n";
    md += &model_errors(plan, o);
    md += &super::shared_passes::table(plan, &o.rows);
    md += &flicker_table(plan, o);
    md += &super::visibility::report_table(plan, &o.rows);
    md += &super::bounce_axis::report(&o.bounce_rows);
    md += "\n## Ratios\n\nEach from the rows of one visibility.\n\n\
| scene | visibility | measure | value | detail |\n| --- | --- | --- | ---: | --- |\n";
    for r in ratios {
        md += &format!(
            "| {} | {} | {} | {} | {} |\n",
            r.scene,
            r.visibility,
            r.measure,
            fmt_value(r.value),
            r.detail
        );
    }
    for s in &plan.scenes {
        md += &format!(
            "\n## {}\n\n| method | visibility | setting | indirect ms (min) | total ms | RMSE indirect | RMSE truth | RMSE final | FLIP | flicker | light-patch evals | memory MiB |\n\
| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
            s.name
        );
        for r in o.rows.iter().filter(|r| r.scene == s.name) {
            md += &format!(
                "| {}{} | {} | {} | {} ({}) | {} | {:.4} | {} | {:.4} | {:.4} | {} | {} | {} |\n",
                r.method,
                if r.is_default { " *" } else { "" },
                r.visibility,
                r.label,
                cell(r.indirect_ms.map(|v| format!("{v:.1}"))),
                cell(r.indirect_ms_min.map(|v| format!("{v:.1}"))),
                cell(r.total_ms.map(|v| format!("{v:.1}"))),
                r.rel_rmse_indirect,
                cell(r.truth.rel_rmse_indirect.map(|v| format!("{v:.4}"))),
                r.rel_rmse_final,
                r.flip,
                cell(r.flicker.map(|v| format!("{v:.4}"))),
                cell(r.light_patch_evals),
                cell(
                    r.gpu_memory_bytes
                        .map(|v| format!("{:.2}", v as f64 / 1048576.0))
                ),
            );
        }
    }
    md += "\n`*`: the method's default setting (gallery, per-pass chart). RMSE indirect, RMSE final and \
FLIP are against the dense reference with the row's visibility.\n";
    md
}

/// Each scene's model error: the dense reference against the path-traced
/// truth, what every VPL method shares (it ignores indirect visibility),
/// with how the truth was made and what its mask left out.
fn model_errors(plan: &Plan, o: &Outcome) -> String {
    let target = plan
        .truth_noise
        .map_or("the target".to_string(), |n| format!("{:.0}%", 100.0 * n));
    let bounces = plan.bounces().words();
    let mut md = format!("## Model error\n\nThe dense reference (every RSM texel a VPL, no indirect visibility) \
against the path-traced truth ({bounces} with visibility, samples doubled until its own noise is under \
{target}, or under less where a truth traced before for a tighter target is reused), over the pixels away \
from geometric and direct-shadow edges (docs/algorithm.md section 6.6): what every VPL method without \
visibility shares. A method can read below it where its own errors and the missing occlusion partly \
cancel, so compare methods against the reference. With exact visibility (`--visibility exact`: one ray \
per pixel and VPL, on the CPU, at the middle frame) the dense reference shows the floor of the VPL model \
itself; with each further visibility of the run (`voxels N`: the grid, N cells a side), its own dense \
reference. The truth's noise adds to every error against it in quadrature.\n\n");
    // The visibilities of the references but `none`: a column each.
    let reference = |s: &str, v: &str| {
        o.rows.iter().find(|r| {
            r.scene == s && r.method == crate::methods::REFERENCE.name() && r.visibility == v
        })
    };
    let others: Vec<&str> = visibilities(&o.rows)
        .into_iter()
        .filter(|&v| {
            v != "none"
                && o.rows
                    .iter()
                    .any(|r| r.method == crate::methods::REFERENCE.name() && r.visibility == v)
        })
        .collect();
    md += "| scene | model error |";
    for v in &others {
        md += &format!(" with {v} |");
    }
    md += " with exact visibility | truth spp | truth noise | pixels left out |\n| --- | ---: |";
    md += &" ---: |".repeat(others.len() + 4);
    md += "\n";
    for s in &plan.scenes {
        let Some(r) = reference(&s.name, "none") else {
            continue;
        };
        let t = &r.truth;
        let with: String = others
            .iter()
            .map(|v| {
                let e = reference(&s.name, v).and_then(|r| r.truth.rel_rmse_indirect);
                format!(" {} |", cell(e.map(|v| format!("{v:.4}"))))
            })
            .collect();
        md += &format!(
            "| {} | {} |{with} {} | {} | {} | {} |\n",
            s.name,
            cell(t.rel_rmse_indirect.map(|v| format!("{v:.4}"))),
            cell(t.floor.map(|v| format!("{v:.4}"))),
            cell(t.spp.map(|v| format!("{v:.0}"))),
            cell(t.noise.map(|v| format!("{v:.4}"))),
            cell(t.left_out.map(|v| format!("{:.1}%", 100.0 * v))),
        );
    }
    md
}

/// Writes every output of a run into its folder (`files::written`, in its
/// order).
pub fn write_all(plan: &Plan, o: &Outcome) -> Result<()> {
    let dir = &plan.out_dir;
    let b = &plan.base;
    let ratios = ratios(&o.rows);
    let scenes: Vec<String> = plan.scenes.iter().map(|s| s.name.clone()).collect();
    let json = json!({
        "device": o.device,
        "driver": o.driver,
        "width": b.width,
        "height": b.height,
        "rsm": b.rsm_resolution,
        "frames": plan.frames,
        "timing_frames": plan.timing_frames,
        "quick": plan.quick,
        "scenes": scenes,
        "visibilities": visibilities(&o.rows),
        "bounces": super::bounces::of_rows(&o.rows),
        "ratios": ratios,
        "rows": o.rows,
        "bounce_axis": o.bounce_rows,
    });
    crate::output::write_text(
        &dir.join(files::RESULTS_JSON),
        &serde_json::to_string_pretty(&json)?,
    )?;
    crate::output::write_text(&dir.join(files::RESULTS_CSV), &rows::to_csv(&o.rows))?;
    super::charts::speed_vs_error(dir, &o.rows, &scenes)?;
    super::charts::speed_vs_truth(dir, &o.rows, &scenes)?;
    super::charts::flicker(dir, &o.rows, &scenes)?;
    super::charts::passes(dir, &o.rows, &scenes)?;
    let methods: Vec<&str> = plan.methods.iter().map(|m| m.name()).collect();
    let passes: Vec<(String, &str)> = plan
        .passes()
        .iter()
        .map(|p| (p.visibility_label(), p.image_suffix()))
        .collect();
    super::gallery::gallery(dir, &o.rows, &scenes, &methods, &passes)?;
    crate::output::write_text(&dir.join(files::REPORT), &markdown(plan, o, &ratios, ""))?;
    Ok(())
}
