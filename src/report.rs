//! Per-pass GPU timings: the JSON written by `--timings` and the table the CLI prints.

use crate::renderer::{median, FrameStats};
use anyhow::{Context as _, Result};
use serde::Serialize;
use std::path::Path;

#[derive(Clone, Debug, Serialize)]
pub struct PassReport {
    pub name: String,
    /// True for passes that exist only for indirect light (docs/algorithm.md section 6).
    pub indirect: bool,
    pub gpu_ms_median: Option<f64>,
    pub gpu_ms_min: Option<f64>,
    /// Pipeline statistics (the counting frame, the last). On lavapipe this
    /// counts rejected blocks too.
    pub fragment_invocations: Option<u64>,
    pub compute_invocations: Option<u64>,
    /// Occlusion query (the counting frame): fragments that passed depth and
    /// stencil tests.
    pub samples_passed: Option<u64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct TimingReport {
    pub device: String,
    pub driver: String,
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub rsm: u32,
    pub method: String,
    pub frames: usize,
    pub passes: Vec<PassReport>,
    /// Median over frames of the sum of all pass times.
    pub total_gpu_ms_median: Option<f64>,
    /// Median over frames of the sum of the indirect passes' times.
    pub indirect_gpu_ms_median: Option<f64>,
    /// Median CPU-measured time from submit to fence, for comparison.
    pub wall_ms_median: f64,
    /// Multiresolution patches per level (level 0 first), last frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub patches_per_level: Option<Vec<u32>>,
    /// Light patches evaluated per eye-space patch (and, for a source that chooses them per frame, how many it chose).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub light_patches: Option<crate::debug_view::LightPatchStats>,
    /// Animation time of the frame (sequences).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<f32>,
}

/// Identifies the run a report belongs to.
pub struct RunInfo<'a> {
    pub device: &'a str,
    pub driver: &'a str,
    pub scene: &'a str,
    pub width: u32,
    pub height: u32,
    pub rsm: u32,
    pub method: &'a str,
}

pub fn build(info: &RunInfo, stats: &FrameStats) -> TimingReport {
    // The pass list and counts of the counting frame (a run without one, such
    // as a benchmark's timing-only frames, lists the last frame's passes).
    let counts = stats
        .counts()
        .or(stats.frames.last().map(|f| f.as_slice()))
        .unwrap_or_default();
    let passes = counts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let times: Vec<f64> = stats.timed().filter_map(|f| f.get(i)?.gpu_ms).collect();
            PassReport {
                name: p.name.to_string(),
                indirect: p.kind.indirect,
                gpu_ms_median: median(&times),
                gpu_ms_min: times.iter().copied().reduce(f64::min),
                fragment_invocations: p.fragment_invocations,
                compute_invocations: p.compute_invocations,
                samples_passed: p.samples_passed,
            }
        })
        .collect();
    TimingReport {
        device: info.device.into(),
        driver: info.driver.into(),
        scene: info.scene.into(),
        width: info.width,
        height: info.height,
        rsm: info.rsm,
        method: info.method.into(),
        frames: stats.frames.len(),
        passes,
        total_gpu_ms_median: stats.gpu_ms_median(false),
        indirect_gpu_ms_median: stats.gpu_ms_median(true),
        wall_ms_median: median(&stats.timed_wall_ms()).unwrap_or(0.0),
        patches_per_level: stats.patches_per_level.clone(),
        light_patches: None,
        time: None,
    }
}

/// Writes `report` as pretty JSON to `path`, creating its folder: the one
/// place a timings file is written (GPU methods and the path tracer alike).
pub fn write_json(path: &Path, report: &TimingReport) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let text = serde_json::to_string_pretty(report)?;
    crate::output::write_text(path, &text)
}

/// Patches per level against the area of all layers (what an unstenciled
/// gather would shade).
pub fn patch_table(counts: &[u32], total_area: u64) -> String {
    let mut out = String::from("level  patches   pixels each\n");
    for (l, c) in counts.iter().enumerate() {
        out += &format!("{l:>5} {c:>9} {:>13}\n", 1u64 << (2 * l));
    }
    let total: u64 = counts.iter().map(|&c| c as u64).sum();
    out += &format!(
        "total {total:>9} patches = {:.2}% of the {total_area} texels in all layers\n",
        100.0 * total as f64 / total_area as f64
    );
    out
}

fn ms(v: Option<f64>) -> String {
    v.map_or("n/a".into(), |v| format!("{v:.3}"))
}

fn count(v: Option<u64>) -> String {
    v.map_or("-".into(), |v| v.to_string())
}

/// The report as an aligned text table.
pub fn table(r: &TimingReport) -> String {
    let mut out = format!(
        "{} | {} | {}x{} | rsm {} | method {} | {} frame(s)\n",
        r.device, r.driver, r.width, r.height, r.rsm, r.method, r.frames
    );
    out += &format!(
        "{:<12} {:>10} {:>10} {:>14} {:>14}\n",
        "pass", "median ms", "min ms", "frag invoc.", "samples passed"
    );
    for p in &r.passes {
        out += &format!(
            "{:<12} {:>10} {:>10} {:>14} {:>14}{}\n",
            p.name,
            ms(p.gpu_ms_median),
            ms(p.gpu_ms_min),
            count(p.fragment_invocations),
            count(p.samples_passed),
            if p.indirect { "  (indirect)" } else { "" }
        );
    }
    out += &format!(
        "{:<12} {:>10}   indirect {} ms, wall {:.3} ms\n",
        "total",
        ms(r.total_gpu_ms_median),
        ms(r.indirect_gpu_ms_median),
        r.wall_ms_median
    );
    out
}

#[cfg(test)]
mod tests {
    use super::{build, RunInfo};
    use crate::renderer::FrameStats;
    use crate::vk::profiler::{PassKind, PassSample};

    /// One pass of `ms`, with a count when the frame counted.
    fn frame(ms: f64, counted: bool) -> Vec<PassSample> {
        vec![PassSample {
            name: "gather",
            kind: PassKind {
                graphics: true,
                indirect: true,
            },
            gpu_ms: Some(ms),
            fragment_invocations: counted.then_some(7),
            compute_invocations: counted.then_some(0),
            samples_passed: counted.then_some(5),
        }]
    }

    fn stats(frames: &[(f64, bool)]) -> FrameStats {
        FrameStats {
            frames: frames.iter().map(|&(ms, c)| frame(ms, c)).collect(),
            counted: frames.iter().map(|&(_, c)| c).collect(),
            wall_ms: frames.iter().map(|&(ms, _)| ms + 0.5).collect(),
            ..Default::default()
        }
    }

    const INFO: RunInfo = RunInfo {
        device: "",
        driver: "",
        scene: "",
        width: 1,
        height: 1,
        rsm: 1,
        method: "",
    };

    #[test]
    fn times_leave_out_the_counting_frame_unless_every_frame_counted() {
        // The counting frame's 9 ms (its queries' cost) stays out of the times.
        let s = stats(&[(1.0, false), (2.0, false), (9.0, true)]);
        let r = build(&INFO, &s);
        assert_eq!(r.passes[0].gpu_ms_median, Some(1.5));
        assert_eq!(r.passes[0].gpu_ms_min, Some(1.0));
        assert_eq!(r.passes[0].samples_passed, Some(5));
        assert_eq!(s.gpu_ms_median(true), Some(1.5));
        assert_eq!(r.wall_ms_median, 2.0);
        // A one-frame run counts and times in the same frame.
        let one = stats(&[(9.0, true)]);
        assert_eq!(build(&INFO, &one).passes[0].gpu_ms_median, Some(9.0));
        // Timing-only frames still list their passes, without counts.
        let timing = build(&INFO, &stats(&[(1.0, false), (3.0, false)]));
        assert_eq!(timing.passes[0].gpu_ms_median, Some(2.0));
        assert_eq!(timing.passes[0].samples_passed, None);
    }
}
