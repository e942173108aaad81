//! `cargo bench --bench light_space`: indirect time and error of HISR, Basic
//! ISR and multires-gather with 256, 1024 and 4096 VPLs, measured in one run
//! on the built-in Cornell box at 512x512 with a 256x256 RSM. The reference is
//! the dense gather of every RSM texel (65,536 VPLs) through the same
//! eye-space patches, so the error is the light-space choice alone. Then the
//! issue-12 goals as ratios from the same run: HISR's time at Basic ISR's
//! error and at 4096 VPLs' error, against theirs. `ISR_BENCH_SIZE=256` for a
//! quicker run. Times are the least indirect time of 3 frames (after one
//! warm-up) in each of 3 rounds over all rows (`ISR_BENCH_ROUNDS`): on a
//! shared CPU the least disturbed frame is the steadiest measure, and rounds
//! spread a slow spell over every row. Writes `target/bench/light_space.json`.

use isr::methods::{hisr, multires_gather};
use isr::regular_vpls::VPLS;
use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::RenderSettings;
use isr::vk::{Gpu, GpuOptions};
use serde_json::json;

struct Run {
    label: String,
    indirect_ms: f64,
    patches_per_eye_patch: f64,
    indirect: Vec<[f32; 4]>,
}

/// Frames timed per row and round (after one warm-up frame).
const FRAMES: u32 = 3;

fn run(gpu: &Gpu, label: &str, s: &RenderSettings, frames: u32) -> anyhow::Result<Run> {
    let scene = cornell_box();
    let mut r = Renderer::new(gpu, &scene, s)?;
    r.render_frames(1, |_| {})?;
    // No counting frame: the counts are not needed here (`Profiler`).
    let stats = r.render_frames_counting(frames, false, |_| {})?;
    let m = r.readback_multires()?.unwrap();
    let light = isr::debug_view::light_patch_stats(&m, None);
    let indirect = r.readback()?.indirect;
    eprintln!("{label}: done");
    Ok(Run {
        label: label.into(),
        indirect_ms: stats.gpu_ms_min(true).unwrap_or(f64::NAN),
        patches_per_eye_patch: light.per_patch_mean,
        indirect,
    })
}

fn main() -> anyhow::Result<()> {
    let gpu = Gpu::new(&GpuOptions::default())?;
    // ISR_BENCH_SIZE=256 for a quicker run.
    let size: u32 = std::env::var("ISR_BENCH_SIZE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(512);
    let base = RenderSettings {
        width: size,
        height: size,
        rsm_resolution: 256,
        ..Default::default()
    };
    let gather = |vpls| {
        base.clone()
            .with_method(multires_gather::KEY)
            .with(&VPLS, vpls)
    };
    let hisr = |tau| base.clone().with_method(hisr::KEY).with(&hisr::TAU, tau);
    let reference = run(&gpu, "dense (65536 VPLs)", &gather(65536), 1)?;
    let mut configs: Vec<(String, RenderSettings)> = Vec::new();
    for n in [256, 1024, 4096] {
        configs.push((format!("multires-gather {n}"), gather(n)));
    }
    configs.push((
        "isr (base 64)".into(),
        base.clone().with_method(isr::methods::isr::KEY),
    ));
    // The HISR curve at its default depth (8: single texels at RSM 256),
    // where tau sets the error; then depth 6, whose finest patches are
    // those of 4096 regular VPLs; the talk's absolute tau at depth 6 (the
    // defaults before relative tau); one point without tiles (every fragment
    // traverses from the roots) for comparison.
    for tau in [0.5, 0.2, 0.1, 0.05, 0.02, 0.01] {
        configs.push((format!("hisr tau {tau}"), hisr(tau)));
    }
    for tau in [0.5, 0.2, 0.05] {
        configs.push((
            format!("hisr tau {tau}, depth 6"),
            hisr(tau).with(&hisr::MAX_DEPTH, 6),
        ));
    }
    for tau in [0.2, 0.05, 0.01] {
        configs.push((
            format!("absolute tau {tau}, depth 6"),
            hisr(tau)
                .with(&hisr::MAX_DEPTH, 6)
                .with(&hisr::TAU_MODE, hisr::TauMode::Absolute),
        ));
    }
    configs.push((
        "hisr tau 0.2, no tiles".into(),
        hisr(0.2).with(&hisr::TILE_LEVEL, 0),
    ));
    // Rounds over every row in turn, each row's time the least over all its
    // frames: a slow spell of the shared machine then touches every row alike
    // instead of whichever rows ran during it.
    let rounds: u32 = std::env::var("ISR_BENCH_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    let mut runs: Vec<Run> = Vec::new();
    for round in 0..rounds.max(1) {
        for (i, (label, s)) in configs.iter().enumerate() {
            let r = run(&gpu, &format!("{label} (round {})", round + 1), s, FRAMES)?;
            match runs.get_mut(i) {
                Some(best) => best.indirect_ms = best.indirect_ms.min(r.indirect_ms),
                None => runs.push(Run {
                    label: label.clone(),
                    ..r
                }),
            }
        }
    }
    let mut rows = Vec::new();
    println!(
        "{:<24} {:>12} {:>18} {:>14}",
        "method", "indirect ms", "patches/eye patch", "rel. RMSE"
    );
    let mut points = Vec::new(); // (label, ms, error)
    for r in &runs {
        let (mut err, mut norm) = (0.0f64, 0.0f64);
        for (a, b) in r.indirect.iter().zip(&reference.indirect) {
            for k in 0..3 {
                err += (a[k] as f64 - b[k] as f64).powi(2);
                norm += (b[k] as f64).powi(2);
            }
        }
        let rmse = (err / norm).sqrt();
        println!(
            "{:<24} {:>12.1} {:>18.1} {:>14.4}",
            r.label, r.indirect_ms, r.patches_per_eye_patch, rmse
        );
        rows.push(json!({"method": r.label, "indirect_ms": r.indirect_ms, "patches_per_eye_patch": r.patches_per_eye_patch, "relative_rmse": rmse}));
        points.push((r.label.clone(), r.indirect_ms, rmse));
    }
    // The goals as ratios from this run: HISR's time at another
    // method's error, interpolated on HISR's front (the settings no other
    // HISR setting beats in both time and error; log time against log error
    // between the two that bracket it).
    let hisr: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.0.starts_with("hisr tau") && !p.0.ends_with("no tiles"))
        .map(|p| (p.1, p.2))
        .collect();
    let mut curve: Vec<(f64, f64)> = hisr
        .iter()
        .filter(|a| !hisr.iter().any(|b| b.0 < a.0 && b.1 < a.1))
        .copied()
        .collect();
    curve.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut goals = Vec::new();
    for (target, want) in [("isr (base 64)", 1.0), ("multires-gather 4096", 4.0)] {
        let Some(&(_, ms, error)) = points.iter().find(|p| p.0 == target) else {
            continue;
        };
        let line = match hisr_time_at(&curve, error) {
            Some(hisr_ms) => format!(
                "at {target}'s error {error:.4}: hisr {hisr_ms:.1} ms, {target} {ms:.1} ms: {:.2}x faster (goal {want}x)",
                ms / hisr_ms
            ),
            None => format!(
                "at {target}'s error {error:.4}: not reached by the hisr curve (lowest error {:.4})",
                curve.iter().map(|c| c.1).fold(f64::INFINITY, f64::min)
            ),
        };
        println!("{line}");
        goals.push(line);
    }
    println!("reference: {} ms indirect", reference.indirect_ms);
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(
        dir.join("light_space.json"),
        serde_json::to_string_pretty(
            &json!({"device": gpu.info.name, "width": size, "height": size, "rsm": 256, "runs": rows, "goals": goals}),
        )?,
    )?;
    Ok(())
}

/// HISR's time at `error` on `curve` ((ms, error) by falling error), log-log
/// interpolated between the two points that bracket it; at errors above
/// its cheapest point, that point's time.
fn hisr_time_at(curve: &[(f64, f64)], error: f64) -> Option<f64> {
    // An error above the curve's cheapest point: that point reaches it, in
    // its time (interpolating would need a cheaper point than any measured).
    if let Some(&(t, e)) = curve.first() {
        if error >= e {
            return Some(t);
        }
    }
    curve.windows(2).find_map(|w| {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        let (lo, hi) = (e0.min(e1), e0.max(e1));
        if !(lo..=hi).contains(&error) {
            return None;
        }
        if e0 == e1 {
            return Some(t0.min(t1));
        }
        let f = (error.ln() - e0.ln()) / (e1.ln() - e0.ln());
        Some((t0.ln() + f * (t1.ln() - t0.ln())).exp())
    })
}
