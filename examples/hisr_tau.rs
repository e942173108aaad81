//! The table of docs/algorithm.md section 4.3: on every bench scene at its
//! bench size, HISR's error against the dense gather through the same
//! eye-space patches (every RSM texel a VPL) at several taus, beside 4096
//! regular VPLs', with the light patches per eye-space patch and the least
//! indirect time of a few frames. A measurement, not a check (what `--tau`
//! means is held by `tests/hisr_tau.rs`).
//!
//!     cargo run --release --example hisr_tau [-- OPTIONS]
//!
//! Options: `--scenes a,b` (default: every bench scene), `--taus 0.2,0.05`
//! (default 0.2,0.05,0.01), `--frames N` timed (default 3), `--mode
//! absolute` (default relative), `--depth full` (down to single RSM texels,
//! so that tau alone sets the error; default: the default max depth),
//! `--size N` (image and RSM, default: each scene's bench size), `--kernel
//! centre` (default second-order), `--out DIR` (default `out/hisr_tau`).
//! Prints Markdown tables and writes them to `DIR/hisr_tau.md`.

use anyhow::{bail, Context as _, Result};
use isr::bench::metrics::{geometry_mask, relative_rmse};
use isr::bench::scenes;
use isr::methods::hisr;
use isr::passes::rsm_tree::{PatchKernel, PATCH_KERNEL};
use isr::regular_vpls::VPLS;
use isr::renderer::Renderer;
use isr::scene::Scene;
use isr::settings::{Method, RenderSettings};
use isr::vk::{Gpu, GpuOptions};
use std::path::PathBuf;

/// The command line.
struct Options {
    scenes: Vec<String>,
    taus: Vec<f32>,
    frames: u32,
    mode: hisr::TauMode,
    full_depth: bool,
    size: Option<u32>,
    kernel: PatchKernel,
    out: PathBuf,
}

impl Options {
    fn parse() -> Result<Self> {
        let mut o = Options {
            scenes: scenes::group("all")
                .context("the bench's scene group `all`")?
                .into_iter()
                .map(str::to_string)
                .collect(),
            taus: vec![0.2, 0.05, 0.01],
            frames: 3,
            mode: hisr::TauMode::Relative,
            full_depth: false,
            size: None,
            kernel: PatchKernel::SecondOrder,
            out: PathBuf::from("out/hisr_tau"),
        };
        let mut args = std::env::args().skip(1);
        while let Some(flag) = args.next() {
            let value = args
                .next()
                .with_context(|| format!("{flag} takes a value"))?;
            match flag.as_str() {
                "--scenes" => o.scenes = value.split(',').map(str::to_string).collect(),
                "--taus" => {
                    o.taus = value
                        .split(',')
                        .map(|t| t.parse().with_context(|| format!("--taus: {t}")))
                        .collect::<Result<_>>()?
                }
                "--frames" => o.frames = value.parse().context("--frames")?,
                "--mode" => {
                    o.mode = match value.as_str() {
                        "relative" => hisr::TauMode::Relative,
                        "absolute" => hisr::TauMode::Absolute,
                        _ => bail!("--mode relative|absolute, not {value}"),
                    }
                }
                "--depth" => {
                    o.full_depth = match value.as_str() {
                        "full" => true,
                        "default" => false,
                        _ => bail!("--depth full|default, not {value}"),
                    }
                }
                "--size" => o.size = Some(value.parse().context("--size")?),
                "--kernel" => {
                    o.kernel = match value.as_str() {
                        "centre" => PatchKernel::Centre,
                        "second-order" => PatchKernel::SecondOrder,
                        _ => bail!("--kernel centre|second-order, not {value}"),
                    }
                }
                "--out" => o.out = PathBuf::from(value),
                _ => bail!(
                    "unknown option {flag} (see the comment at the top of examples/hisr_tau.rs)"
                ),
            }
        }
        Ok(o)
    }
}

/// One render: the indirect image, the pixels with geometry, light patches
/// per eye-space patch and the least indirect time of `frames` frames.
struct Measured {
    indirect: Vec<[f32; 4]>,
    mask: Vec<bool>,
    per_patch: f64,
    ms: f64,
}

/// A table's cell: the error against the dense gather, light patches per
/// eye-space patch and the least indirect time (ms).
struct Cell {
    error: f64,
    per_patch: f64,
    ms: f64,
}

fn measure(gpu: &Gpu, scene: &Scene, s: &RenderSettings, frames: u32) -> Result<Measured> {
    let mut r = Renderer::new(gpu, scene, s)?;
    let stats = r.render_frames(frames, |_| {})?;
    let out = r.readback()?;
    let m = r
        .readback_multires()?
        .context("a multiresolution method's buffer")?;
    Ok(Measured {
        mask: geometry_mask(&out.position),
        indirect: out.indirect,
        per_patch: isr::debug_view::light_patch_stats(&m, None).per_patch_mean,
        ms: stats.gpu_ms_min(true).unwrap_or(f64::NAN),
    })
}

/// A Markdown table: a header row, its rule (the first column left-aligned,
/// the others right) and the rows.
fn table(header: &[String], rows: &[Vec<String>]) -> String {
    let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
    let rule: Vec<String> = (0..header.len())
        .map(|i| if i == 0 { "---" } else { "---:" }.to_string())
        .collect();
    let mut md = line(header) + &line(&rule);
    for r in rows {
        md += &line(r);
    }
    md
}

fn main() -> Result<()> {
    let o = Options::parse()?;
    let gpu = Gpu::new(&GpuOptions::default())?;
    let mut header = vec!["scene".to_string(), "4096 VPLs".to_string()];
    header.extend(o.taus.iter().map(|t| format!("hisr tau {t}")));
    // Per scene: 4096 VPLs, then each tau.
    let mut measured: Vec<(String, Vec<Cell>)> = vec![];
    for name in &o.scenes {
        let bench = scenes::find(name)?;
        let scene = scenes::build(name)?;
        let (size, rsm) = match o.size {
            Some(n) => (n, n),
            None => bench.size.unwrap_or((128, 128)),
        };
        let at = |method: &'static str| {
            RenderSettings {
                width: size,
                height: size,
                rsm_resolution: rsm,
                method: Method::new(method),
                ..Default::default()
            }
            .with(&PATCH_KERNEL, o.kernel)
        };
        let dense = measure(
            &gpu,
            &scene,
            &at("multires-gather").with(&VPLS, rsm * rsm),
            1,
        )?;
        if !dense.mask.iter().any(|&g| g) {
            bail!("{name}: no pixel has geometry");
        }
        let row = |m: Measured| Cell {
            error: relative_rmse(&m.indirect, &dense.indirect, &dense.mask),
            per_patch: m.per_patch,
            ms: m.ms,
        };
        let mut cells = vec![row(measure(
            &gpu,
            &scene,
            &at("multires-gather").with(&VPLS, 4096),
            o.frames,
        )?)];
        for &tau in &o.taus {
            let mut s = at("hisr")
                .with(&hisr::TAU, tau)
                .with(&hisr::TAU_MODE, o.mode);
            if o.full_depth {
                s = s.with(&hisr::MAX_DEPTH, rsm.ilog2());
            }
            cells.push(row(measure(&gpu, &scene, &s, o.frames)?));
        }
        eprintln!("{name}: measured");
        measured.push((name.clone(), cells));
    }

    let errors: Vec<Vec<String>> = measured
        .iter()
        .map(|(name, cells)| {
            std::iter::once(name.clone())
                .chain(
                    cells
                        .iter()
                        .map(|c| format!("{:.5} ({:.0})", c.error, c.per_patch)),
                )
                .collect()
        })
        .chain(std::iter::once(
            std::iter::once("spread (largest / smallest)".to_string())
                .chain((0..header.len() - 1).map(|k| {
                    let column = measured.iter().map(|(_, c)| c[k].error);
                    let (lo, hi) =
                        column.fold((f64::MAX, 0.0f64), |(lo, hi), e| (lo.min(e), hi.max(e)));
                    // A column of exact images (every texel a VPL) has none.
                    if lo > 0.0 {
                        format!("{:.2}", hi / lo)
                    } else {
                        "-".to_string()
                    }
                }))
                .collect(),
        ))
        .collect();
    let times: Vec<Vec<String>> = measured
        .iter()
        .map(|(name, cells)| {
            std::iter::once(name.clone())
                .chain(cells.iter().map(|c| format!("{:.2}", c.ms)))
                .collect()
        })
        .collect();
    let md = format!(
        "# HISR's error against the dense gather\n\n\
         Device: {} ({}). Tau mode {}, max depth {}, patch kernel {}, {} timed frames. \
         Relative RMSE of the indirect image against the dense gather through the same \
         eye-space patches (every RSM texel a VPL); light patches per eye-space patch in \
         brackets.\n\n{}\n## Least indirect time of the timed frames (ms)\n\n{}",
        gpu.info.name,
        gpu.info.driver,
        format!("{:?}", o.mode).to_lowercase(),
        if o.full_depth {
            "single texels"
        } else {
            "the default"
        },
        match o.kernel {
            PatchKernel::Centre => "centre",
            PatchKernel::SecondOrder => "second-order",
        },
        o.frames,
        table(&header, &errors),
        table(&header, &times),
    );
    print!("{md}");
    let path = o.out.join("hisr_tau.md");
    isr::output::write_text(&path, &md)?;
    println!("\nwrote {}", path.display());
    Ok(())
}
