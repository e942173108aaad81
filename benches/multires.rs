//! `cargo bench --bench multires`: what early stencil rejection saves in the
//! multiresolution gather (docs/algorithm.md section 3, step 6), for the built-in
//! Cornell box at 512x512 with 256 VPLs, and where the remaining cost goes.
//!
//! Lavapipe shades stencil-survivors in 4x2-pixel groups: a group with one
//! live texel is shaded whole. So besides the fragments that pass (occlusion
//! query) this counts the live 4x2 groups per level from the stencil, which
//! predicts the work lavapipe really does. Writes `target/bench/multires.json`.

use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::RenderSettings;
use isr::vk::{Gpu, GpuOptions};
use serde_json::json;

fn gather_ms(stats: &isr::renderer::FrameStats, name: &str) -> f64 {
    let times: Vec<f64> = stats
        .timed()
        .filter_map(|f| f.iter().find(|p| p.name == name)?.gpu_ms)
        .collect();
    isr::renderer::median(&times).unwrap_or(f64::NAN)
}

fn main() -> anyhow::Result<()> {
    let gpu = Gpu::new(&GpuOptions::default())?;
    let scene = cornell_box();
    let base = RenderSettings {
        width: 512,
        height: 512,
        rsm_resolution: 512,
        method: isr::methods::multires_gather::KEY,
        ..Default::default()
    };
    let mut report = serde_json::Map::new();
    let mut results = Vec::new();
    for stencil in [true, false] {
        let s = base.clone().with(&isr::multires::STENCIL, stencil);
        let mut r = Renderer::new(&gpu, &scene, &s)?;
        r.render_frames(1, |_| {})?;
        let frames = if stencil { 10 } else { 3 };
        let stats = r.render_frames(frames, |_| {})?;
        let last = stats.counts().unwrap();
        let gather = last.iter().find(|p| p.name == "gather").unwrap();
        let m = r.readback_multires()?.unwrap();
        let area = r.multires().unwrap().total_area();
        // Live 4x2 groups per level, from the stencil.
        let mut groups = Vec::new();
        let mut patches = Vec::new();
        for l in 0..=m.levels {
            let (w, h) = (m.width >> l, m.height >> l);
            let live = |x: u32, y: u32| {
                x < w && y < h && m.stencil[l as usize][(y * m.width + x) as usize] == 1
            };
            let mut g = 0u64;
            let mut p = 0u64;
            for gy in (0..h).step_by(2) {
                for gx in (0..w).step_by(4) {
                    let n = (0..8).filter(|i| live(gx + i % 4, gy + i / 4)).count() as u64;
                    g += (n > 0) as u64;
                    p += n;
                }
            }
            groups.push(g);
            patches.push(p);
        }
        let ms = gather_ms(&stats, "gather");
        println!(
            "stencil {:<3}: gather {ms:8.2} ms, fragments passed {:>7} of {area} texels in all layers ({:.2}%), fragment invocations {:?}",
            if stencil { "on" } else { "off" },
            gather.samples_passed.unwrap_or(0),
            100.0 * gather.samples_passed.unwrap_or(0) as f64 / area as f64,
            gather.fragment_invocations
        );
        if stencil {
            println!(
                "level  patches  live 4x2 groups  texels shaded (8 per group)  patches / shaded"
            );
            for l in 0..groups.len() {
                println!(
                    "{l:>5} {:>8} {:>16} {:>28} {:>16.2}",
                    patches[l],
                    groups[l],
                    groups[l] * 8,
                    patches[l] as f64 / (groups[l] * 8).max(1) as f64
                );
            }
            let shaded: u64 = groups.iter().map(|g| g * 8).sum();
            println!(
                "all   {:>8} {:>16} {:>28} {:>16.2}",
                patches.iter().sum::<u64>(),
                groups.iter().sum::<u64>(),
                shaded,
                patches.iter().sum::<u64>() as f64 / shaded as f64
            );
            report.insert("live_groups_per_level".into(), json!(groups));
            report.insert("patches_per_level".into(), json!(patches));
            report.insert("texels_shaded_by_groups".into(), json!(shaded));
        }
        report.insert(
            format!("stencil_{}", if stencil { "on" } else { "off" }),
            json!({"gather_ms_median": ms, "samples_passed": gather.samples_passed, "fragment_invocations": gather.fragment_invocations,
                   "passes": last.iter().map(|p| json!({"name": p.name, "gpu_ms_median": gather_ms(&stats, p.name)})).collect::<Vec<_>>()}),
        );
        report.insert("total_area".into(), json!(area));
        results.push(ms);
    }
    println!(
        "gather with the stencil costs {:.1}% of the gather without it",
        100.0 * results[0] / results[1]
    );
    report.insert("device".into(), json!(gpu.info.name));
    report.insert("on_over_off".into(), json!(results[0] / results[1]));
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(
        dir.join("multires.json"),
        serde_json::to_string_pretty(&report)?,
    )?;
    Ok(())
}
