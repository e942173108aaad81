//! Method `lpv` against the one-bounce path-traced truth (docs/algorithm.md
//! section 8): on every bench scene and the bunny room, at rest, 128x128
//! with an RSM of 128, how much indirect light LPV puts on the image and
//! how far it is from the truth pixel by pixel. The truth is traced at the
//! same size until its noise is under 3% (minutes a scene on lavapipe's
//! CPUs; every point shares it).
//!
//!     cargo run --release --example lpv_energy [-- [--scenes a,b] [POINT...]]
//!
//! `--scenes` names bench scenes (default: the stress scenes and `bunny`,
//! whose mesh is read from the archive folder, `../shared/scenes`). A POINT
//! is LPV's parameters as `name=value` pairs joined by commas
//! (`lpv-size=16,lpv-iterations=16`); `default` is the method's defaults,
//! and the only point when none is given.
//!
//! Per scene and point it prints the energy ratio, LPV's irradiance summed
//! over the pixels that see geometry over the truth's on the same pixels
//! (1 is right; the goal is within 2x, between 0.5 and 2), and the relative
//! RMSE against the truth over its mask (edges left out, the truth's noise
//! taken out, `Truth::model_error`).

use anyhow::{bail, Context as _, Result};
use isr::bench::truth::{trace, ShadowMaps, Truth};
use isr::methods::lpv::{self, grid, Layout};
use isr::renderer::Renderer;
use isr::scene::Scene;
use isr::settings::{Params, RenderSettings};
use isr::vk::{Gpu, GpuOptions};

/// The truth's noise target (relative RMSE of its indirect image): small
/// beside LPV's errors, and far smaller in a sum over the image.
const NOISE: f64 = 0.03;

/// Image side and RSM resolution: the bench's stress-scene size.
const SIZE: u32 = 128;

/// The scenes measured by default: the stress scenes and the bunny room.
fn default_scenes() -> Vec<String> {
    let mut v: Vec<String> = isr::bench::scenes::SCENES
        .iter()
        .map(|s| s.name.to_string())
        .collect();
    v.push("bunny".into());
    v
}

/// A point's parameters from `name=value,...` (`default`: none).
fn point(text: &str) -> Result<Params> {
    let mut p = Params::new();
    if text == "default" {
        return Ok(p);
    }
    for pair in text.split(',') {
        let Some((name, value)) = pair.split_once('=') else {
            bail!("'{pair}' is not name=value");
        };
        let Some(param) = lpv::PARAMS.iter().find(|q| q.name() == name) else {
            let names: Vec<&str> = lpv::PARAMS.iter().map(|q| q.name()).collect();
            bail!("unknown parameter {name}; LPV's are {}", names.join(", "));
        };
        let v = param
            .parse(value)
            .map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
        p.insert(param.name(), v);
    }
    Ok(p)
}

fn settings(params: &Params) -> RenderSettings {
    let mut s = RenderSettings {
        width: SIZE,
        height: SIZE,
        rsm_resolution: SIZE,
        ..Default::default()
    }
    .with_method(lpv::KEY);
    s.params.overlay(params);
    s
}

/// LPV's energy over the truth's on the pixels that see geometry, and its
/// relative RMSE against the truth.
fn compare(t: &Truth, position: &[[f32; 4]], indirect: &[[f32; 4]]) -> (f64, f64) {
    let (mut lpv, mut truth) = (0.0f64, 0.0f64);
    for ((p, e), q) in position.iter().zip(indirect).zip(&t.image.indirect) {
        if p[3] > 0.0 {
            lpv += (e[0] + e[1] + e[2]) as f64;
            truth += (q[0] + q[1] + q[2]) as f64;
        }
    }
    (lpv / truth, t.model_error(indirect))
}

/// Where the cascades lie this frame, for the table: each one's cell size.
fn cells(r: &Renderer, s: &RenderSettings) -> String {
    let c = grid::cascades(&r.frame_uniforms(), &Layout::of(s));
    let sizes: Vec<String> = c.iter().map(|c| format!("{:.3}", c.cell)).collect();
    sizes.join("/")
}

fn main() -> Result<()> {
    let mut scenes = default_scenes();
    let mut points = vec![];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--scenes" {
            let value = args.next().context("--scenes takes a value")?;
            scenes = value.split(',').map(str::to_string).collect();
        } else {
            points.push((a.clone(), point(&a)?));
        }
    }
    if points.is_empty() {
        points.push(("default".into(), Params::new()));
    }
    let gpu = Gpu::new(&GpuOptions::default())?;
    println!(
        "LPV against the one-bounce truth, {SIZE}x{SIZE}, RSM {SIZE}, at rest ({}, {})\n",
        gpu.info.name, gpu.info.driver
    );
    println!(
        "| scene | point | label | cells (m) | energy / truth | rel. RMSE | truth spp, noise |"
    );
    println!("| --- | --- | --- | --- | ---: | ---: | ---: |");
    for name in &scenes {
        let mut scene: Scene = isr::bench::scenes::build(name)?;
        scene.animation = None;
        let mut truth: Option<Truth> = None;
        for (text, params) in &points {
            let s = settings(params);
            isr::methods::find(lpv::KEY)?.check(&s)?;
            let mut r = Renderer::new(&gpu, &scene, &s)?;
            r.render_frames(1, |_| {})?;
            let out = r.readback()?;
            let t = match &truth {
                Some(t) => t,
                None => {
                    eprintln!("{name}: tracing the truth");
                    let shadows =
                        ShadowMaps::new(r.light_views(), r.render_origin(), SIZE, s.pcf_radius);
                    truth.insert(trace(&scene, &out, &shadows, NOISE, 1, |spp, noise| {
                        eprintln!("{name}: {spp} spp, noise {noise:.4}")
                    }))
                }
            };
            let (ratio, error) = compare(t, &out.position, &out.indirect);
            let label = isr::methods::find(lpv::KEY)?.label(&s);
            println!(
                "| {name} | {text} | {label} | {} | {ratio:.3} | {error:.3} | {}, {:.4} |",
                cells(&r, &s),
                t.spp,
                t.noise
            );
        }
    }
    Ok(())
}
