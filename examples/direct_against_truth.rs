//! Direct light against the path tracer's (docs/algorithm.md section 2.2):
//! the relative RMSE of the rasterized direct image against `pathtrace`'s
//! direct layer (exact shadow rays, noise-free), over the truth mask
//! (section 6.6: away from geometric edges and from the shadow band PCF
//! blurs), at each RSM resolution, with the shadow map of its own size
//! (`RenderSettings::shadow_size`) and, with `--shadow-as-rsm`, as it was
//! when the RSM's depth was the shadow map (the RSM's size and square), for
//! - `sibenik`: the Sibenik nave of `tests/shadow_leaks.rs` under its spot and its point light;
//! - `sponza`: the Sponza atrium under its sun (`assets/archive/sponza.scene.json`, t = 0);
//! - `court`: the sun-lit court of `tests/shadow_leaks.rs` under each of its three low suns.
//!
//! ```text
//! cargo run --release --example direct_against_truth [-- [--size N] [--rsm 128,256,...] [--scenes a,b] [--dump DIR] [--shadow N | --shadow-as-rsm]]
//! ```
//!
//! Default: 512x512 (`isr render`'s size), RSM 128 to 2048, every scene.
//! Prints one Markdown table: the error and, after a slash, the share of
//! compared pixels lit where the path tracer has shadow (leaks, direct
//! light over 1% of the scene's mean). `--dump DIR` writes a PNG per
//! scene and RSM: the path tracer's direct light in grey, leaks in red,
//! pixels left out of the comparison in blue. A last column gives the
//! median GPU time of passes `shadow` and `rsm` over 3 frames at the
//! largest RSM.

use anyhow::{bail, Context, Result};
use isr::bench::metrics::relative_rmse;
use isr::bench::truth::{truth_mask, ShadowMaps};
use isr::pathtrace::PathTraceSettings;
use isr::readback::Readback;
use isr::renderer::Renderer;
use isr::scene::Scene;
use isr::settings::{Method, RenderSettings};
use isr::vk::{Gpu, GpuOptions};

#[path = "../tests/common/court.rs"]
mod court;
#[path = "../tests/common/sibenik.rs"]
mod sibenik;

struct Args {
    size: u32,
    rsm: Vec<u32>,
    scenes: Vec<String>,
    dump: Option<std::path::PathBuf>,
    as_rsm: bool,
    shadow: u32,
}

fn args() -> Result<Args> {
    let mut a = Args {
        size: 512,
        rsm: vec![128, 256, 512, 1024, 2048],
        scenes: vec!["sibenik".into(), "sponza".into(), "court".into()],
        dump: None,
        as_rsm: false,
        shadow: 0,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        if flag == "--shadow-as-rsm" {
            a.as_rsm = true;
            continue;
        }
        let value = it.next().with_context(|| format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--size" => a.size = value.parse()?,
            "--rsm" => a.rsm = value.split(',').map(str::parse).collect::<Result<_, _>>()?,
            "--scenes" => a.scenes = value.split(',').map(String::from).collect(),
            "--dump" => a.dump = Some(value.into()),
            "--shadow" => a.shadow = value.parse()?,
            _ => bail!("unknown option {flag}"),
        }
    }
    Ok(a)
}

/// The scenes by name: each a label and its scene.
fn scenes(name: &str) -> Result<Vec<(String, Scene)>> {
    let archive = |file: &str| -> Result<Scene> {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("assets/archive")
            .join(file);
        isr::scene::load_file(&path, &Default::default())
            .with_context(isr::scene::description::archive_hint)
    };
    Ok(match name {
        "sibenik" => sibenik::lights()
            .into_iter()
            .map(|(name, light)| {
                let mut s = sibenik::nave()?;
                s.lights = vec![light];
                Ok((format!("Sibenik, {name}"), s))
            })
            .collect::<Result<_>>()?,
        "sponza" => vec![("Sponza atrium, sun".into(), archive("sponza.scene.json")?)],
        "court" => court::low_suns()
            .into_iter()
            .map(|(name, sun)| (format!("court, {name}"), court::court(sun)))
            .collect(),
        _ => bail!("unknown scene {name} (sibenik, sponza, court)"),
    })
}

/// Direct light only (`--method none`) at `--size`, RSM `rsm`; with
/// `--shadow-as-rsm` the shadow map at the RSM's size and square, else at
/// `--shadow` (0: its default).
fn settings(a: &Args, rsm: u32) -> RenderSettings {
    let (size, as_rsm) = (a.size, a.as_rsm);
    RenderSettings {
        width: size,
        height: size,
        rsm_resolution: rsm,
        shadow_resolution: if as_rsm { rsm } else { a.shadow },
        fit_sun_shadow: !as_rsm,
        method: Method::new("none"),
        ..Default::default()
    }
}

/// Median GPU milliseconds of passes `shadow` and `rsm` (summed over light
/// views) over 3 frames of `scene` at `s`.
fn pass_ms(gpu: &Gpu, scene: &Scene, s: &RenderSettings) -> Result<(f64, f64)> {
    let mut r = Renderer::new(gpu, scene, s)?;
    let stats = r.render_frames(4, |_| {})?;
    let of = |name: &str| {
        let per_frame: Vec<f64> = stats
            .timed()
            .map(|f| {
                f.iter()
                    .filter(|p| p.name == name || p.name.starts_with(&format!("{name}[")))
                    .filter_map(|p| p.gpu_ms)
                    .sum()
            })
            .collect();
        isr::renderer::median(&per_frame).unwrap_or(f64::NAN)
    };
    Ok((of("shadow"), of("rsm")))
}

/// The error of `scene`'s direct light at `s` against `traced`, and the
/// share of compared pixels that leak; with `dump`, the PNG of `--dump`.
fn measure(
    gpu: &Gpu,
    scene: &Scene,
    s: &RenderSettings,
    traced: &Readback,
    dump: Option<&std::path::Path>,
) -> Result<(f64, f64)> {
    let mut r = Renderer::new(gpu, scene, s)?;
    r.render_frames(1, |_| {})?;
    let raster = r.readback()?;
    let views = r.light_views().to_vec();
    let shadows = ShadowMaps::new(&views, r.render_origin(), s.shadow_size(), s.pcf_radius);
    drop(r);
    let compared = truth_mask(&raster, &traced.direct, &shadows);
    let mask = &compared.mask;
    let e = relative_rmse(&raster.direct, &traced.direct, mask);
    let sum = |d: &[f32; 4]| d[0] + d[1] + d[2];
    let kept: Vec<usize> = (0..mask.len()).filter(|&k| mask[k]).collect();
    let mean = kept.iter().map(|&k| sum(&traced.direct[k])).sum::<f32>() / kept.len() as f32;
    let leaking = |k: usize| sum(&traced.direct[k]) == 0.0 && sum(&raster.direct[k]) > 0.01 * mean;
    let leaks = kept.iter().filter(|&&k| leaking(k)).count();
    if let Some(path) = dump {
        let rgba: Vec<u8> = (0..mask.len())
            .flat_map(|k| {
                let grey = (255.0 * (sum(&traced.direct[k]) / (3.0 * mean)).min(1.0)) as u8;
                match (mask[k], leaking(k)) {
                    (true, true) => [255, 0, 0, 255],
                    (true, false) => [grey, grey, grey, 255],
                    (false, _) => [grey / 2, grey / 2, 128 + grey / 2, 255],
                }
            })
            .collect();
        isr::output::write_png(path, raster.width, raster.height, &rgba)?;
    }
    Ok((e, leaks as f64 / kept.len().max(1) as f64))
}

fn main() -> Result<()> {
    let a = args()?;
    let gpu = Gpu::new(&GpuOptions::default())?;
    let mut header = "| scene |".to_string();
    for r in &a.rsm {
        header += &format!(" `--rsm {r}` |");
    }
    header += " `shadow` / `rsm` ms |";
    println!("{header}\n|---|{}", "---|".repeat(a.rsm.len() + 1));
    for name in &a.scenes {
        for (label, scene) in scenes(name)? {
            let traced = isr::pathtrace::render(
                &scene,
                &PathTraceSettings {
                    width: a.size,
                    height: a.size,
                    spp: 1,
                    seed: 1,
                    exposure: 1.0,
                    bounces: isr::bounces::Bounces::ONE,
                },
                |_, _| {},
            );
            let mut row = format!("| {label} |");
            for &rsm in &a.rsm {
                let dump = a.dump.as_ref().map(|dir| {
                    let name: String = label
                        .chars()
                        .map(|c| if c.is_alphanumeric() { c } else { '-' })
                        .collect();
                    dir.join(format!("{name}-rsm{rsm}.png"))
                });
                if let Some(d) = &a.dump {
                    std::fs::create_dir_all(d)?;
                }
                let s = settings(&a, rsm);
                let (e, leaks) = measure(&gpu, &scene, &s, &traced, dump.as_deref())?;
                row += &format!(" {:.1}% / {:.2}% |", 100.0 * e, 100.0 * leaks);
            }
            let last = settings(&a, *a.rsm.iter().max().unwrap_or(&512));
            let (shadow, rsm) = pass_ms(&gpu, &scene, &last)?;
            row += &format!(" {shadow:.1} / {rsm:.1} |");
            println!("{row}");
        }
    }
    Ok(())
}
