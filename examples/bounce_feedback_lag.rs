//! The lag and the cost of `--bounce-feedback on` (docs/algorithm.md
//! section 5.9, "Temporal feedback"): the light of a scene jumps from its
//! pose at the start of the animation to the pose at a quarter of its length, after
//! the feedback had settled on the first; frame by frame after the jump, the
//! relative RMSE of the indirect image against the one the feedback settles
//! on at the new pose (section 6.1, over the pixels with geometry), and the
//! frames until it stays within 1%. The settled image is the last of
//! `--frames` after the jump; its own distance from `--bounces inf` without
//! feedback is printed too. Cost: the bounce passes' GPU time a frame
//! (the least of the timed frames: 12 without feedback, `--frames` with
//! it), with and without feedback.
//!
//!     cargo run --release --example bounce_feedback_lag [-- [--size N] [--frames N] [--scenes a,b]]
//!
//! Defaults: `rsm-gather` with the voxel grid's visibility, 64x64, RSM 64,
//! 40 frames on each side of the jump, the scenes whose light alone moves
//! (`cornell`, `slats`, the archive's `bunny`). Prints a Markdown table.

use anyhow::{bail, Context as _, Result};
use glam::DVec3;
use isr::bounce::FEEDBACK;
use isr::bounces::{Bounces, BOUNCES};
use isr::readback::Readback;
use isr::renderer::{FrameStats, Renderer};
use isr::scene::Scene;
use isr::settings::{Method, RenderSettings};
use isr::visibility::{Visibility, VISIBILITY};
use isr::vk::{Gpu, GpuOptions};

fn rel_rmse(a: &Readback, b: &Readback) -> f64 {
    let v = |p: &[f32; 4]| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    let (mut num, mut den) = (0.0, 0.0);
    for i in (0..a.indirect.len()).filter(|&i| b.position[i][3] > 0.0) {
        num += (v(&a.indirect[i]) - v(&b.indirect[i])).length_squared();
        den += v(&b.indirect[i]).length_squared();
    }
    (num / den).sqrt()
}

/// The least over timed frames (the least disturbed on a shared machine) of
/// the summed GPU time (ms) of the passes whose names start with `prefix`.
fn pass_ms(stats: &FrameStats, prefix: &str) -> f64 {
    let per_frame: Vec<f64> = stats
        .timed()
        .map(|f| {
            f.iter()
                .filter(|p| p.name.starts_with(prefix))
                .filter_map(|p| p.gpu_ms)
                .sum()
        })
        .collect();
    per_frame.into_iter().fold(f64::INFINITY, f64::min)
}

struct Row {
    scene: String,
    /// The settled image before the jump against the one after it.
    jump: f64,
    errors: Vec<f64>,
    lag: Option<usize>,
    from_inf: f64,
    ms_feedback: f64,
    ms_inf: f64,
    /// `bounce-feedback` and the `bounce-propagate` it replaces.
    ms_one: f64,
    ms_propagate: f64,
}

fn measure(gpu: &Gpu, name: &str, size: u32, frames: u32) -> Result<Row> {
    let scene: Scene = isr::bench::scenes::build(name)?;
    let quarter = scene
        .animation_duration()
        .with_context(|| format!("{name} has no animation"))?
        * 0.25;
    let settings = |feedback: bool| {
        RenderSettings {
            width: size,
            height: size,
            rsm_resolution: 64,
            method: Method::new("rsm-gather"),
            ..RenderSettings::DEFAULT
        }
        .with(&VISIBILITY, Visibility::Voxels)
        .with(&BOUNCES, Bounces::Infinite)
        .with(&FEEDBACK, feedback)
    };
    let mut inf = Renderer::new(gpu, &scene, &settings(false))?;
    inf.update(&scene.state_at(quarter))?;
    let stats = inf.render_frames(12, |_| {})?;
    let (every, ms_inf) = (inf.readback()?, pass_ms(&stats, "bounce-"));
    let ms_propagate = pass_ms(&stats, "bounce-propagate");
    drop(inf);
    let mut r = Renderer::new(gpu, &scene, &settings(true))?;
    r.update(&scene.state_at(0.0))?;
    let stats = r.render_frames(frames, |_| {})?;
    let ms_feedback = pass_ms(&stats, "bounce-");
    let ms_one = pass_ms(&stats, "bounce-feedback");
    let before = r.readback()?;
    r.update(&scene.state_at(quarter))?;
    let mut images = vec![];
    for _ in 0..frames {
        r.render_frames(1, |_| {})?;
        images.push(r.readback()?);
    }
    let settled = images.last().unwrap();
    let errors: Vec<f64> = images.iter().map(|i| rel_rmse(i, settled)).collect();
    // The first frame after which the image stays within 1%.
    let lag = (0..errors.len())
        .find(|&k| errors[k..].iter().all(|&e| e < 0.01))
        .map(|k| k + 1)
        .filter(|&k| k < errors.len());
    Ok(Row {
        scene: name.to_string(),
        jump: rel_rmse(&before, settled),
        from_inf: rel_rmse(settled, &every),
        errors,
        lag,
        ms_feedback,
        ms_inf,
        ms_one,
        ms_propagate,
    })
}

fn main() -> Result<()> {
    let mut size = 64;
    let mut frames = 40;
    let mut scenes: Vec<String> = ["cornell", "slats", "bunny"].map(String::from).to_vec();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().with_context(|| format!("{a} takes a value"));
        match a.as_str() {
            "--size" => size = value()?.parse()?,
            "--frames" => frames = value()?.parse()?,
            "--scenes" => scenes = value()?.split(',').map(str::to_string).collect(),
            other => bail!("unknown argument {other}; takes --size N, --frames N, --scenes a,b"),
        }
    }
    if frames < 10 {
        bail!("--frames {frames}: at least 10, so that the last frame has settled");
    }
    let gpu = Gpu::new(&GpuOptions::default())?;
    let mut md = format!(
        "`--bounce-feedback on` after the light jumps (`rsm-gather`, voxel visibility, \
         `--bounces inf`, {size}x{size}, RSM 64): relative RMSE of the indirect image against \
         the one it settles on, frames 1, 2, 4, 8 and 16 after the jump; frames until it stays \
         within 1%; the settled image against `--bounces inf` without feedback; the bounce \
         passes' GPU time a frame (lavapipe, the least over the frames) with feedback and without. The jump: the image \
         settled before it against the one after; in brackets, `bounce-feedback` and the \
         `bounce-propagate` it replaces.\n\n\
         | scene | jump | 1 | 2 | 4 | 8 | 16 | lag (frames) | settled vs inf | bounce ms feedback | bounce ms inf |\n\
         | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n"
    );
    for name in &scenes {
        eprintln!("{name}: {size}x{size}, {frames} frames each side of the jump");
        let r = measure(&gpu, name, size, frames)?;
        let at = |k: usize| {
            r.errors
                .get(k - 1)
                .map_or("-".into(), |e| format!("{:.1}%", 100.0 * e))
        };
        let row = format!(
            "| {} | {:.0}% | {} | {} | {} | {} | {} | {} | {:.2}% | {:.0} ({:.1}) | {:.0} ({:.1}) |\n",
            r.scene,
            100.0 * r.jump,
            at(1),
            at(2),
            at(4),
            at(8),
            at(16),
            r.lag.map_or(format!("> {frames}"), |k| k.to_string()),
            100.0 * r.from_inf,
            r.ms_feedback,
            r.ms_one,
            r.ms_inf,
            r.ms_propagate
        );
        eprint!("{row}");
        md += &row;
    }
    println!("{md}");
    Ok(())
}
