//! Method `lpv` against the one-bounce path-traced truth (docs/algorithm.md
//! section 8): on every bench scene and the bunny room, at rest, 128x128
//! with an RSM of 128, how much indirect light LPV puts on the image and
//! how far it is from the truth pixel by pixel. The truth is traced at the
//! same size until its noise is under 3% (minutes a scene on lavapipe's
//! CPUs; every point shares it).
//!
//!     cargo run --release --example lpv_energy [-- [--scenes a,b] [--scale S] [--out DIR] [--cache DIR] [POINT...]]
//!
//! `--scenes` names bench scenes (default: the stress scenes and `bunny`,
//! whose mesh is read from the archive folder, `../shared/scenes`);
//! `--scale` scales every scene by S about the world's origin (camera,
//! lights and znear with it; default 1): a room like it of another size,
//! since LPV's cells are powers of two and a room fills them differently
//! within an octave (the ratios do not depend on the light's intensity, so
//! it is left as it is); `--out`
//! writes, per scene and point, `DIR/SCENE-K.png`: the truth's indirect
//! irradiance on the left, point K's on the right, both grey, white at four
//! times the truth's mean (to see where the light goes); `--cache` is where
//! each scene's truth is kept for the next run (default
//! `target/lpv_energy`). A POINT
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
use glam::{Mat4, Vec3};
use isr::bench::truth::{trace, ShadowMaps, Truth, TruthMask};
use isr::bounces::Bounces;
use isr::methods::lpv::{self, grid, Layout};
use isr::readback::Readback;
use isr::renderer::Renderer;
use isr::scene::Scene;
use isr::settings::{Params, RenderSettings};
use isr::vk::{Gpu, GpuOptions};
use std::path::PathBuf;

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

/// `scene` scaled by `s` about the origin: its instances, camera, znear and
/// lights (the camera's node stays rigid, its position scaled).
fn scaled(mut scene: Scene, s: f32) -> Scene {
    let m = Mat4::from_scale(Vec3::splat(s));
    for i in &mut scene.instances {
        i.world_from_object = m * i.world_from_object;
    }
    let c = &mut scene.camera;
    c.world_from_camera.w_axis = (c.world_from_camera.w_axis.truncate() * s).extend(1.0);
    c.znear *= s;
    for l in &mut scene.lights {
        l.position *= s;
        l.range = l.range.map(|r| r * s);
    }
    scene
}

/// The truth's indirect image, mask, samples and noise, as raw words in
/// `file` (a truth takes minutes; every run with the same scene and scale
/// shares it).
fn save(file: &std::path::Path, t: &Truth) -> Result<()> {
    std::fs::create_dir_all(file.parent().context("a cache file has a folder")?)?;
    let mut words: Vec<f32> = vec![t.spp as f32, t.noise as f32];
    words.extend(t.image.indirect.iter().flatten());
    words.extend(t.mask.mask.iter().map(|&m| m as u8 as f32));
    std::fs::write(file, bytemuck::cast_slice(&words))?;
    Ok(())
}

/// The truth `save` wrote for a frame like `image`, if there is one of its
/// size.
fn load(file: &std::path::Path, image: &Readback) -> Option<Truth> {
    let bytes = std::fs::read(file).ok()?;
    let words: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let n = image.indirect.len();
    if words.len() != 2 + 5 * n {
        return None;
    }
    let mut truth = image.clone();
    truth.indirect = words[2..2 + 4 * n]
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect();
    let mask: Vec<bool> = words[2 + 4 * n..].iter().map(|&m| m > 0.5).collect();
    Some(Truth {
        image: truth,
        bounces: Bounces::ONE,
        mask: TruthMask {
            geometry: image.position.iter().filter(|p| p[3] > 0.0).count(),
            mask,
            geometric_edges: 0,
            shadow_edges: 0,
        },
        spp: words[0] as u32,
        noise: words[1] as f64,
        noises: vec![words[1] as f64],
    })
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

/// The truth's and LPV's indirect irradiance side by side, grey (the sum
/// of the channels), white at four times the truth's mean over `position`'s
/// geometry, as an RGBA8 image twice as wide as the frame.
fn side_by_side(t: &Truth, position: &[[f32; 4]], indirect: &[[f32; 4]]) -> Vec<u8> {
    let sum = |e: &[f32; 4]| e[0] + e[1] + e[2];
    let seen: Vec<f32> = position
        .iter()
        .zip(&t.image.indirect)
        .filter(|(p, _)| p[3] > 0.0)
        .map(|(_, e)| sum(e))
        .collect();
    let white = 4.0 * seen.iter().sum::<f32>() / seen.len().max(1) as f32;
    let grey = |e: &[f32; 4]| {
        let v = (sum(e) / white).clamp(0.0, 1.0).powf(1.0 / 2.2);
        let g = (v * 255.0).round() as u8;
        [g, g, g, 255]
    };
    let w = t.image.width as usize;
    let mut out = vec![];
    for (a, b) in t.image.indirect.chunks(w).zip(indirect.chunks(w)) {
        out.extend(a.iter().flat_map(grey));
        out.extend(b.iter().flat_map(grey));
    }
    out
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
    let mut out: Option<PathBuf> = None;
    let mut scale = 1.0f32;
    let mut cache = PathBuf::from("target/lpv_energy");
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--scenes" {
            let value = args.next().context("--scenes takes a value")?;
            scenes = value.split(',').map(str::to_string).collect();
        } else if a == "--scale" {
            scale = args.next().context("--scale takes a number")?.parse()?;
        } else if a == "--cache" {
            cache = args.next().context("--cache takes a folder")?.into();
        } else if a == "--out" {
            out = Some(args.next().context("--out takes a folder")?.into());
        } else {
            points.push((a.clone(), point(&a)?));
        }
    }
    if points.is_empty() {
        points.push(("default".into(), Params::new()));
    }
    let gpu = Gpu::new(&GpuOptions::default())?;
    println!(
        "LPV against the one-bounce truth, {SIZE}x{SIZE}, RSM {SIZE}, at rest, scenes scaled by \
         {scale} ({}, {})\n",
        gpu.info.name, gpu.info.driver
    );
    println!(
        "| scene | point | label | cells (m) | energy / truth | rel. RMSE | truth spp, noise |"
    );
    println!("| --- | --- | --- | --- | ---: | ---: | ---: |");
    for name in &scenes {
        let mut scene = scaled(isr::bench::scenes::build(name)?, scale);
        scene.animation = None;
        let mut truth: Option<Truth> = None;
        for (k, (text, params)) in points.iter().enumerate() {
            let s = settings(params);
            isr::methods::find(lpv::KEY)?.check(&s)?;
            let mut r = Renderer::new(&gpu, &scene, &s)?;
            r.render_frames(1, |_| {})?;
            let image = r.readback()?;
            let t = match &truth {
                Some(t) => t,
                None => {
                    let file = cache.join(format!("{name}-{scale}.bin"));
                    let t = match load(&file, &image) {
                        Some(t) => t,
                        None => {
                            eprintln!("{name}: tracing the truth");
                            let shadows = ShadowMaps::new(
                                r.light_views(),
                                r.render_origin(),
                                SIZE,
                                s.pcf_radius,
                            );
                            let t = trace(&scene, &image, &shadows, NOISE, 1, Bounces::ONE, {
                                |spp, noise| eprintln!("{name}: {spp} spp, noise {noise:.4}")
                            });
                            save(&file, &t)?;
                            t
                        }
                    };
                    truth.insert(t)
                }
            };
            let (ratio, error) = compare(t, &image.position, &image.indirect);
            if let Some(dir) = &out {
                let png = side_by_side(t, &image.position, &image.indirect);
                let path = dir.join(format!("{name}-{k}.png"));
                isr::output::write_png(&path, 2 * SIZE, SIZE, &png)?;
            }
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
