//! The share of the indirect light each bounce carries (docs/algorithm.md
//! section 5.4, "Bounces"): every bench scene (`bench::scenes::SCENES`) and
//! the archive's bunny room, at rest, path-traced with every bounce
//! (`--bounces inf`), over the pixels the bench compares with its truth
//! (`truth_mask`: geometry away from geometric and direct-shadow edges).
//!
//!     cargo run --release --example bounce_shares [-- [--size N] [--spp N] [--scenes a,b] [--out FILE]]
//!
//! Defaults: 128x128 (the bench's size, RSM 128 for the mask's shadow
//! bands), 1,024 samples per pixel (5 minutes on 2 CPU cores), every scene,
//! `out/bounce_shares.md`. The
//! samples are traced as two halves of independent seeds: a share's noise
//! is half the difference of the halves' shares (the noise of their mean).
//! Prints a Markdown table and writes it to the file.

use anyhow::{bail, Context as _, Result};
use isr::bench::truth::{truth_mask, ShadowMaps};
use isr::bounces::{Bounces, LAYERS};
use isr::pathtrace::{render as trace, PathTraceSettings};
use isr::readback::Readback;
use isr::renderer::Renderer;
use isr::settings::{Method, RenderSettings};
use isr::vk::{Gpu, GpuOptions};
use std::path::PathBuf;

/// Each bounce's share of the indirect irradiance over `mask`, all three
/// channels summed: bounce 1, 2, 3 and 4 on.
fn shares(r: &Readback, mask: &[bool]) -> [f64; LAYERS.len()] {
    let sum = |layer: &[[f32; 4]]| -> f64 {
        (0..mask.len())
            .filter(|&i| mask[i])
            .map(|i| layer[i][..3].iter().map(|&v| v as f64).sum::<f64>())
            .sum()
    };
    let by_bounce: Vec<f64> = r.bounces.iter().map(|l| sum(l)).collect();
    let total: f64 = by_bounce.iter().sum();
    std::array::from_fn(|k| by_bounce[k] / total)
}

struct Row {
    scene: String,
    pixels: usize,
    kept: usize,
    shares: [f64; 4],
    noise: [f64; 4],
    seconds: f64,
}

fn measure(gpu: &Gpu, name: &str, size: u32, spp: u32) -> Result<Row> {
    let mut scene = isr::bench::scenes::build(name)?;
    scene.animation = None;
    // The bench's G-buffer and shadow maps, for its mask.
    let settings = RenderSettings {
        width: size,
        height: size,
        rsm_resolution: 128,
        method: Method::new("none"),
        ..RenderSettings::DEFAULT
    };
    let mut r = Renderer::new(gpu, &scene, &settings)?;
    r.render_frames(1, |_| {})?;
    let g = r.readback()?;
    let views = r.light_views().to_vec();
    let shadows = ShadowMaps::new(
        &views,
        r.render_origin(),
        settings.shadow_size(),
        settings.pcf_radius,
    );
    drop(r);
    let started = std::time::Instant::now();
    let half = |seed: u64| {
        trace(
            &scene,
            &PathTraceSettings {
                width: size,
                height: size,
                spp: spp / 2,
                seed,
                exposure: 1.0,
                bounces: Bounces::Infinite,
            },
            |_, _| {},
        )
    };
    let (a, b) = (half(1), half(2));
    let seconds = started.elapsed().as_secs_f64();
    let mask = truth_mask(&g, &a.direct, &shadows);
    let (sa, sb) = (shares(&a, &mask.mask), shares(&b, &mask.mask));
    Ok(Row {
        scene: name.to_string(),
        pixels: mask.geometry,
        kept: mask.kept(),
        shares: std::array::from_fn(|k| 0.5 * (sa[k] + sb[k])),
        noise: std::array::from_fn(|k| 0.5 * (sa[k] - sb[k]).abs()),
        seconds,
    })
}

fn main() -> Result<()> {
    let mut size = 128;
    let mut spp = 1024;
    let mut out = PathBuf::from("out/bounce_shares.md");
    let mut scenes: Vec<String> = isr::bench::scenes::SCENES
        .iter()
        .map(|s| s.name.to_string())
        .chain(["bunny".to_string()])
        .collect();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().with_context(|| format!("{a} takes a value"));
        match a.as_str() {
            "--size" => size = value()?.parse()?,
            "--spp" => spp = value()?.parse()?,
            "--out" => out = value()?.into(),
            "--scenes" => scenes = value()?.split(',').map(str::to_string).collect(),
            other => {
                bail!("unknown argument {other}; takes --size N, --spp N, --scenes a,b, --out FILE")
            }
        }
    }
    if spp < 2 || spp % 2 != 0 {
        bail!("--spp {spp}: an even number of samples, traced as two halves");
    }
    let gpu = Gpu::new(&GpuOptions::default())?;
    let mut rows = vec![];
    for name in &scenes {
        eprintln!("{name}: {size}x{size}, {spp} spp, every bounce");
        let row = measure(&gpu, name, size, spp)?;
        eprintln!("{name}: {:.0} s", row.seconds);
        rows.push(row);
    }
    let threads = rayon::current_num_threads();
    let mut md = format!(
        "Share of the indirect irradiance carried by each bounce (`isr render --method pathtrace \
         --bounces inf`; scenes at rest, {size}x{size}, {spp} samples per pixel on {threads} CPU \
         threads), over the pixels the bench compares with its truth (geometry away from edges); \
         in brackets, the share's noise in percentage points (half the difference of two \
         halves of the samples); the trace's wall seconds.\n\n\
         | scene | pixels kept | bounce 1 | bounce 2 | bounce 3 | bounces 4+ | trace s |\n\
         | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n"
    );
    for r in &rows {
        let cells: Vec<String> = (0..LAYERS.len())
            .map(|k| format!("{:.1}% ({:.2})", 100.0 * r.shares[k], 100.0 * r.noise[k]))
            .collect();
        md += &format!(
            "| {} | {} of {} | {} | {:.0} |\n",
            r.scene,
            r.kept,
            r.pixels,
            cells.join(" | "),
            r.seconds
        );
    }
    println!("{md}");
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&out, &md).with_context(|| format!("cannot write {}", out.display()))?;
    eprintln!("wrote {}", out.display());
    Ok(())
}
