//! `isr view`: the viewer's options, turned into `RenderSettings` with the
//! same defaults as `isr render`.

use super::D;
use crate::settings::{LightTreeSettings, Method, RenderSettings};
use crate::vk::{GpuOptions, Validation};
use crate::{scene, viewer};
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct ViewArgs {
    /// glTF 2.0 scene (.gltf or .glb); the built-in Cornell box when omitted.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Let the scene's buffer and image URIs name files outside its folder.
    #[arg(long)]
    allow_outside_uris: bool,
    /// The method shown first (`M` cycles through the interactive ones).
    #[arg(long, value_enum, default_value_t = D.method)]
    method: Method,
    /// Render width in pixels (also the window's initial width).
    #[arg(long, default_value_t = D.width)]
    width: u32,
    /// Render height in pixels (also the window's initial height).
    #[arg(long, default_value_t = D.height)]
    height: u32,
    /// Reflective shadow map resolution R (R x R, a power of two).
    #[arg(long, default_value_t = D.rsm_resolution)]
    rsm: u32,
    /// Regular VPLs (a power of 4); `,` and `.` change it.
    #[arg(long, default_value_t = D.vpls)]
    vpls: u32,
    /// HISR's error threshold (fraction of the light's peak intensity); `[` and `]` change it.
    #[arg(long, default_value_t = D.light_tree.tau)]
    tau: f32,
    /// Basic ISR's dense starting level, in patches per side.
    #[arg(long, default_value_t = D.light_tree.isr_base)]
    isr_base: u32,
    /// Coarsest level of the multiresolution buffer (default from the size).
    #[arg(long)]
    levels: Option<u32>,
    /// Multiplier on radiance before the sRGB encoding.
    #[arg(long, default_value_t = D.exposure)]
    exposure: f32,
    /// Animation time at the start, seconds.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    time: f32,
    /// Start with the animation paused (`P` plays it).
    #[arg(long)]
    paused: bool,
    /// Timed input, one command a line: `<seconds> key NAME`, `<seconds>
    /// screenshot PATH.png`, `<seconds> resize W H`, `<seconds> quit`; times
    /// count from the first presented frame.
    #[arg(long)]
    script: Option<PathBuf>,
    /// Load the Khronos validation layer with synchronization validation; exit
    /// non-zero if it reports anything.
    #[arg(long)]
    validate: bool,
    /// Device index from `isr devices`.
    #[arg(long)]
    device: Option<usize>,
}

pub fn view(args: ViewArgs) -> Result<()> {
    if !args.time.is_finite() {
        bail!(
            "--time {}: the animation time must be a finite number of seconds",
            args.time
        );
    }
    let interactive = viewer::interactive_methods();
    if !interactive.contains(&args.method) {
        let names: Vec<&str> = interactive.iter().map(|m| m.name()).collect();
        bail!(
            "--method {}: isr view shows the methods that render a frame at once on the GPU ({}); \
             use `isr render --method {}` for it",
            args.method.name(),
            names.join(", "),
            args.method.name()
        );
    }
    // The script is read before any window opens, so its errors come first.
    let script = match &args.script {
        Some(path) => viewer::script::load(path)?,
        None => Vec::new(),
    };
    let scene = match &args.scene {
        Some(path) => scene::gltf_load::load_with(
            path,
            &scene::gltf_load::LoadOptions {
                allow_outside_uris: args.allow_outside_uris,
                ..Default::default()
            },
        )?,
        None => scene::cornell::cornell_box(),
    };
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        rsm_resolution: args.rsm,
        method: args.method,
        exposure: args.exposure,
        vpls: args.vpls,
        light_tree: LightTreeSettings {
            isr_base: args.isr_base,
            tau: args.tau,
            ..D.light_tree
        },
        multires: crate::settings::MultiresSettings {
            levels: args.levels,
            ..D.multires
        },
        ..RenderSettings::default()
    };
    viewer::run(
        &scene,
        viewer::ViewOptions {
            settings,
            gpu: GpuOptions {
                validation: if args.validate {
                    Validation::Required
                } else {
                    Validation::Off
                },
                device_index: args.device,
            },
            script,
            time: args.time,
            paused: args.paused,
        },
    )
}
