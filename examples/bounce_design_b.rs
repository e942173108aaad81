//! The ceiling of "design B" for multiple bounces (docs/algorithm.md
//! section 5.9): the RSM as the secondary source, each texel gathering the
//! first bounce and re-emitting `rho E A`. Such a design carries bounce 2
//! and on only where the re-emitting surface (`y_1`, the one that sends the
//! light on to the surface the camera sees) is seen by a light's RSM. The
//! path tracer (`--bounces inf`) splits each bounce's light by that
//! (`pathtrace::light_seen`): what the light does not see (outside its
//! frusta, facing away, or occluded) design B misses whatever its gathering.
//!
//!     cargo run --release --example bounce_design_b [-- [--size N] [--spp N] [--scenes a,b]]
//!
//! Defaults: 64x64, 256 samples per pixel, the scenes with a spot
//! (`cornell`, `hall`, the archive's `bunny`), a point light
//! (`assets/cornell-point.gltf`) and the sun (`assets/cornell-sun.gltf`,
//! the archive's `sponza`); a few minutes on 2 CPU cores. Over every
//! pixel with geometry, all three channels. Prints a Markdown table.

use anyhow::{bail, Context as _, Result};
use isr::bounces::Bounces;
use isr::pathtrace::light_seen::{split, LightSeenSplit};
use isr::pathtrace::PathTraceSettings;
use isr::renderer::Renderer;
use isr::scene::Scene;
use isr::settings::{Method, RenderSettings};
use isr::vk::{Gpu, GpuOptions};

fn scene(name: &str) -> Result<Scene> {
    let mut scene = match name.strip_suffix(".gltf") {
        Some(_) => isr::scene::load_file(std::path::Path::new(name), &Default::default())?,
        None => isr::bench::scenes::build(name)?,
    };
    scene.animation = None;
    Ok(scene)
}

fn measure(gpu: &Gpu, name: &str, size: u32, spp: u32) -> Result<(LightSeenSplit, f64)> {
    let scene = scene(name).with_context(|| format!("scene {name}"))?;
    // The renderer's light views: the RSMs design B would gather from.
    let settings = RenderSettings {
        width: size,
        height: size,
        method: Method::new("none"),
        ..RenderSettings::DEFAULT
    };
    let r = Renderer::new(gpu, &scene, &settings)?;
    let (views, origin) = (r.light_views().to_vec(), r.render_origin());
    drop(r);
    let started = std::time::Instant::now();
    let s = split(
        &scene,
        &PathTraceSettings {
            width: size,
            height: size,
            spp,
            seed: 1,
            exposure: 1.0,
            bounces: Bounces::Infinite,
        },
        &views,
        origin,
    );
    Ok((s, started.elapsed().as_secs_f64()))
}

fn main() -> Result<()> {
    let mut size = 64;
    let mut spp = 256;
    let mut scenes: Vec<String> = [
        "cornell",
        "assets/cornell-point.gltf",
        "assets/cornell-sun.gltf",
        "hall",
        "bunny",
        "sponza",
    ]
    .map(str::to_string)
    .to_vec();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().with_context(|| format!("{a} takes a value"));
        match a.as_str() {
            "--size" => size = value()?.parse()?,
            "--spp" => spp = value()?.parse()?,
            "--scenes" => scenes = value()?.split(',').map(str::to_string).collect(),
            other => bail!("unknown argument {other}; takes --size N, --spp N, --scenes a,b"),
        }
    }
    let gpu = Gpu::new(&GpuOptions::default())?;
    let pct = |a: f64, b: f64| if b > 0.0 { 100.0 * a / b } else { 0.0 };
    let mut md = format!(
        "Light design B (the RSM as secondary source) cannot carry: `pathtrace --bounces inf`, \
         {size}x{size}, {spp} spp, every pixel with geometry. Unseen: the re-emitting vertex \
         y_1 is outside every RSM frustum, faces away from its light or is occluded from it.\n\n\
         | scene | bounces 2+ / indirect | bounce 2 unseen | bounces 2+ unseen | 2+ any vertex unseen | \
         missed / indirect | bounce 1 unseen (check) | trace s |\n\
         | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n"
    );
    for name in &scenes {
        eprintln!("{name}: {size}x{size}, {spp} spp, every bounce");
        let (s, seconds) = measure(&gpu, name, size, spp)?;
        let total: f64 = s.by_bounce.iter().sum();
        let later: f64 = s.by_bounce[1..].iter().sum();
        let first: f64 = s.first_unseen[1..].iter().sum();
        let any: f64 = s.any_unseen[1..].iter().sum();
        let row = format!(
            "| {name} | {:.1}% | {:.1}% | {:.1}% | {:.1}% | {:.1}% | {:.2}% | {seconds:.0} |\n",
            pct(later, total),
            pct(s.first_unseen[1], s.by_bounce[1]),
            pct(first, later),
            pct(any, later),
            pct(first, total),
            pct(s.first_unseen[0], s.by_bounce[0]),
        );
        eprint!("{row}");
        md += &row;
    }
    println!("{md}");
    Ok(())
}
