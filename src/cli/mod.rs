//! The `isr` command line: argument parsing and the `render`, `devices` and
//! `export-builtin` commands. `main.rs` only calls [`run`].

use crate::output::OutputKind;
use crate::renderer::Renderer;
use crate::settings::{
    LightTreeSettings, Method, MultiresSettings, RenderSettings, Upsample, VplSampling,
};
use crate::vk::{Gpu, GpuOptions, Validation};
use crate::{output, report, scene};
use anyhow::{bail, Context as _, Result};
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

mod runs;
mod view;
use runs::*;

#[derive(Parser)]
#[command(
    name = "isr",
    version,
    about = "Hierarchical image-space radiosity and its baselines, on Vulkan"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene headless and write EXR, PNG and per-pass GPU timings.
    #[command(allow_negative_numbers = true)]
    Render(Box<RenderArgs>),
    /// Every method over its parameter sweep on the stress scenes, against
    /// the dense reference: results.json/.csv, charts, gallery, report.md.
    Bench(Box<crate::bench::BenchArgs>),
    /// Show a scene in a window: fly the camera, move the light, switch
    /// methods, per-pass GPU times on screen (keys: README, "Interactive").
    #[command(allow_negative_numbers = true)]
    View(Box<view::ViewArgs>),
    /// List the Vulkan devices (the index is what --device takes).
    Devices,
    /// Write the built-in Cornell box as a glTF file.
    ExportBuiltin {
        /// Output .gltf path.
        path: PathBuf,
    },
}

/// Every default below comes from `RenderSettings::DEFAULT`, which the
/// library and the benchmarks use too.
const D: RenderSettings = RenderSettings::DEFAULT;

#[derive(Args)]
struct RenderArgs {
    /// glTF 2.0 scene (.gltf or .glb); the built-in Cornell box when omitted.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Let the scene's buffer and image URIs name files outside its folder
    /// (absolute paths, '..', file: URIs, symbolic links out of it).
    #[arg(long)]
    allow_outside_uris: bool,
    /// How indirect light is computed.
    #[arg(long, value_enum, default_value_t = D.method)]
    method: Method,
    /// Output width in pixels.
    #[arg(long, default_value_t = D.width)]
    width: u32,
    /// Output height in pixels.
    #[arg(long, default_value_t = D.height)]
    height: u32,
    /// Reflective shadow map resolution R (R x R, a power of two).
    #[arg(long, default_value_t = D.rsm_resolution)]
    rsm: u32,
    /// Frames to render; timings are medians over them (over all but the last,
    /// which alone counts fragments and invocations, when there are several).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: u32,
    /// Multi-layer OpenEXR output (linear).
    #[arg(long, default_value = "out/render.exr")]
    out: PathBuf,
    /// PNG output (tonemapped sRGB).
    #[arg(long, default_value = "out/render.png")]
    png: PathBuf,
    /// Write per-pass GPU timings as JSON to this file.
    #[arg(long)]
    timings: Option<PathBuf>,
    /// Multiplier on radiance before the PNG's sRGB encoding.
    #[arg(long, default_value_t = D.exposure)]
    exposure: f32,
    /// Load the Khronos validation layer with synchronization validation; exit
    /// non-zero if it reports anything.
    #[arg(long)]
    validate: bool,
    /// Device index from `isr devices` (default: discrete > integrated > virtual > CPU).
    #[arg(long)]
    device: Option<usize>,
    /// Regular VPLs (a power of 4): the sqrt(N) x sqrt(N) level of the RSM quadtree.
    #[arg(long, default_value_t = D.vpls)]
    vpls: u32,
    /// A VPL is its patch's mean, or the patch's centre texel with scaled flux.
    #[arg(long, value_enum, default_value_t = D.vpl_sampling)]
    vpl_sampling: VplSampling,
    /// Coarsest level L of the multiresolution buffer (texels of 2^L x 2^L
    /// pixels); default: about 1/16 of the shorter side (5 at 512).
    #[arg(long)]
    levels: Option<u32>,
    /// Split a texel when its view-depth range relative to its nearest depth,
    /// (max - min) / min, is not below this.
    #[arg(long, default_value_t = D.multires.depth_threshold)]
    depth_threshold: f32,
    /// Split a texel when its normals span this angle (degrees) or more.
    #[arg(long, default_value_t = D.multires.normal_threshold_deg)]
    normal_threshold: f32,
    /// Upsampling of the multiresolution buffer to full resolution.
    #[arg(long, value_enum, default_value_t = D.multires.upsample)]
    upsample: Upsample,
    /// Early stencil rejection in the gather; `off` shades every texel of every
    /// level and masks afterwards (to measure what the stencil saves).
    #[arg(long, value_enum, default_value_t = if D.multires.stencil { OnOff::On } else { OnOff::Off })]
    stencil: OnOff,
    /// Print patch counts per level (also recorded in the timings JSON).
    #[arg(long)]
    stats: bool,
    /// Basic ISR's dense starting level, in patches per side (a power of 2).
    #[arg(long, default_value_t = D.light_tree.isr_base)]
    isr_base: u32,
    /// HISR starts its traversal from 2^s x 2^s light patches.
    #[arg(long, default_value_t = D.light_tree.start_level)]
    start_level: u32,
    /// HISR subdivides at most down to 2^d x 2^d patches (at most log2 of
    /// --rsm; default 6, or log2 of --rsm if smaller); patches spanning a
    /// discontinuity are held to 1/100 of tau.
    #[arg(long)]
    max_depth: Option<u32>,
    /// HISR's error threshold, as a fraction of the light's peak intensity: a
    /// light patch is subdivided while its contribution could exceed tau * I.
    #[arg(long, default_value_t = D.light_tree.tau)]
    tau: f32,
    /// HISR finds the traversal shared by each tile of 2^K, 2^(K+1) and
    /// 2^(K+2) pixels a side once per tile (pass hisr-cut); 0 traverses from
    /// the roots in every fragment.
    /// Same image either way (up to float rounding).
    #[arg(long, default_value_t = D.light_tree.hisr_tile_level)]
    hisr_tile_level: u32,
    /// Light patches merge only when each child lies within this fraction of
    /// its distance to the light from the merged patch's plane.
    #[arg(long, default_value_t = D.light_tree.depth_threshold)]
    light_depth_threshold: f32,
    /// ... and their normals by less than this angle (degrees).
    #[arg(long, default_value_t = D.light_tree.normal_threshold_deg)]
    light_normal_threshold: f32,
    /// --method reference: light-patch evaluations per submission (pixels x
    /// VPLs). The default keeps a submission near half a second on lavapipe;
    /// on a GPU, larger chunks cut the per-submission overhead.
    #[arg(long, default_value_t = D.reference_chunk)]
    reference_chunk: u64,
    /// Indirect samples per pixel for --method pathtrace.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=65536))]
    spp: u32,
    /// Random seed for --method pathtrace.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Restricted splats: a VPL's quad covers only where its irradiance bound
    /// Phi / (pi d^2) exceeds this (W/m^2); 0 gives full-screen splats.
    #[arg(long, default_value_t = D.splat_threshold)]
    splat_threshold: f32,
    /// Extra PNGs next to --png: `levels` colors each pixel by the level of its
    /// patch, `indirect` shows the indirect light alone, `vpl-count` is a heat
    /// map of the light patches evaluated per pixel. Repeatable.
    #[arg(long, value_enum)]
    debug_view: Vec<DebugView>,
    /// Animation time in seconds: the scene's glTF animations (and the
    /// --orbit-* motion) at this time. With --sequence, the first frame's time.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    time: f32,
    /// Write --frames frames at times --time + k / --fps into this folder
    /// (frame_0000.exr, frame_0000.png, ..., timings.json) instead of timing
    /// one frame --frames times.
    #[arg(long)]
    sequence: Option<PathBuf>,
    /// Frames per second of a --sequence.
    #[arg(long, default_value_t = 30.0)]
    fps: f32,
    /// With --sequence, also write the frames as a looping animated GIF,
    /// DIR/sequence.gif, played at --fps.
    #[arg(long, requires = "sequence")]
    gif: bool,
    /// Circle the light about the scene's vertical axis through its initial
    /// position, once per PERIOD seconds, still aimed at the same point.
    #[arg(long, value_name = "PERIOD")]
    orbit_light: Option<f32>,
    /// The same for the camera.
    #[arg(long, value_name = "PERIOD")]
    orbit_camera: Option<f32>,
}

impl RenderArgs {
    /// The scene's frame state at animation time `t`, with the built-in motion.
    fn state_at(&self, scene: &scene::Scene, t: f32) -> scene::FrameState {
        let mut state = scene.state_at(t);
        let pivot = scene::motion::pivot(scene);
        if let Some(period) = self.orbit_light {
            scene::motion::orbit_light(&mut state, pivot, period, t);
        }
        if let Some(period) = self.orbit_camera {
            scene::motion::orbit_camera(&mut state, pivot, period, t);
        }
        state
    }

    /// The timing report of `stats` for this run.
    fn report(
        &self,
        gpu: &Gpu,
        scene: &scene::Scene,
        stats: &crate::renderer::FrameStats,
    ) -> report::TimingReport {
        report::build(
            &report::RunInfo {
                device: &gpu.info.name,
                driver: &gpu.info.driver,
                scene: &scene.name,
                width: self.width,
                height: self.height,
                rsm: self.rsm,
                method: self.method.name(),
            },
            stats,
        )
    }

    /// Where `--debug-view` writes `view`: next to --png, named after it.
    fn debug_view_path(&self, view: DebugView) -> PathBuf {
        let suffix = match view {
            DebugView::Levels => "levels",
            DebugView::Indirect => "indirect",
            DebugView::VplCount => "vpl-count",
        };
        let stem = self
            .png
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        self.png.with_file_name(format!("{stem}-{suffix}.png"))
    }

    fn check_motion(&self) -> Result<()> {
        if !self.time.is_finite() {
            bail!(
                "--time {}: the animation time must be a finite number of seconds",
                self.time
            );
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            bail!("--fps {}: frames per second must be positive", self.fps);
        }
        for (name, p) in [
            ("--orbit-light", self.orbit_light),
            ("--orbit-camera", self.orbit_camera),
        ] {
            if let Some(p) = p {
                if !(p.is_finite() && p > 0.0) {
                    bail!("{name} {p}: the period must be a positive number of seconds");
                }
            }
        }
        Ok(())
    }
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum OnOff {
    On,
    Off,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum DebugView {
    Levels,
    Indirect,
    VplCount,
}

/// A one-line progress bar (redrawn in place): frames, and the submissions of
/// the current frame when there are several (the reference's chunks), with
/// the time left estimated from the time so far.
fn progress_line(p: &crate::renderer::FrameProgress, elapsed: f64) -> String {
    let total = (p.frames * p.submissions) as f64;
    // A frame's completion is reported with submission 0, the parts of a
    // multi-submission frame with 1..submissions.
    let done = if p.frame >= p.frames {
        total
    } else {
        ((p.frame * p.submissions) + p.submission) as f64
    };
    let fraction = (done / total).clamp(0.0, 1.0);
    let width = 30;
    let filled = (fraction * width as f64).round() as usize;
    let left = if fraction > 0.0 {
        elapsed / fraction - elapsed
    } else {
        0.0
    };
    let part = if p.submissions > 1 {
        format!(", part {}/{}", p.submission, p.submissions)
    } else {
        String::new()
    };
    format!(
        "\r[{}{}] {:>3.0}% frame {}/{}{part}, {left:.0} s left ",
        "#".repeat(filled),
        "-".repeat(width - filled),
        fraction * 100.0,
        (p.frame + 1).min(p.frames),
        p.frames
    )
}

/// Parses `std::env::args` and runs the command.
pub fn run() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Render(args) => render(*args),
        Command::Bench(args) => crate::bench::cli(&args),
        Command::View(args) => view::view(*args),
        Command::Devices => devices(),
        Command::ExportBuiltin { path } => {
            let json = scene::export::to_gltf_json(&scene::cornell::cornell_box())?;
            output::write_text(&path, &json)?;
            println!("wrote {}", path.display());
            Ok(())
        }
    }
}

fn devices() -> Result<()> {
    let list = crate::vk::context::list_devices()?;
    if list.is_empty() {
        bail!(
            "no Vulkan device found; {}",
            crate::vk::context::INSTALL_DRIVER_HINT
        );
    }
    for d in list {
        let (ma, mi, pa) = d.api_version;
        println!(
            "{}: {} [{}] driver {} Vulkan {ma}.{mi}.{pa}{}",
            d.index,
            d.name,
            d.kind_name(),
            d.driver,
            d.unusable
                .map(|w| format!(" (unusable: {w})"))
                .unwrap_or_default()
        );
    }
    Ok(())
}

fn render(args: RenderArgs) -> Result<()> {
    args.check_motion()?;
    let needs_multires = args
        .debug_view
        .iter()
        .any(|v| matches!(v, DebugView::Levels | DebugView::VplCount));
    if needs_multires && !args.method.uses_multires() {
        bail!(
            "--debug-view levels and vpl-count need a method with the multiresolution buffer \
             (multires-gather, multires-splat, isr, hisr); --method {} has none",
            args.method.name()
        );
    }
    let debug_pngs: Vec<PathBuf> = args
        .debug_view
        .iter()
        .map(|&v| args.debug_view_path(v))
        .collect();
    let mut outputs = vec![
        (OutputKind::Exr, args.out.as_path()),
        (OutputKind::Png, &args.png),
    ];
    outputs.extend(args.timings.as_deref().map(|t| (OutputKind::Json, t)));
    outputs.extend(
        debug_pngs
            .iter()
            .map(|p| (OutputKind::DebugPng, p.as_path())),
    );
    if args.sequence.is_none() {
        output::check_outputs(&outputs)?;
    } else if let Some(dir) = &args.sequence {
        output::check_sequence_dir(dir)?;
    }
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
    if args.method == Method::Pathtrace {
        // The CPU reference renders the scene posed at --time.
        let state = args.state_at(&scene, args.time);
        let mut posed = scene.clone();
        posed.camera = state.camera;
        posed.lights = state.lights;
        for (inst, m) in posed.instances.iter_mut().zip(&state.instance_transforms) {
            inst.world_from_object = *m;
        }
        return pathtrace(&args, &posed);
    }
    if scene
        .lights
        .iter()
        .any(|l| l.kind == scene::LightKind::Spot && l.outer_cone > crate::view::MAX_RSM_HALF_FOV)
    {
        eprintln!("warning: the spot cone is wider than the RSM's 80 degree half-angle; light beyond it is cut");
    }
    let gpu = Gpu::new(&GpuOptions {
        validation: if args.validate {
            Validation::Required
        } else {
            Validation::Off
        },
        device_index: args.device,
    })?;
    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        rsm_resolution: args.rsm,
        method: args.method,
        exposure: args.exposure,
        vpls: args.vpls,
        vpl_sampling: args.vpl_sampling,
        multires: MultiresSettings {
            levels: args.levels,
            depth_threshold: args.depth_threshold,
            normal_threshold_deg: args.normal_threshold,
            upsample: args.upsample,
            stencil: args.stencil == OnOff::On,
        },
        light_tree: LightTreeSettings {
            depth_threshold: args.light_depth_threshold,
            normal_threshold_deg: args.light_normal_threshold,
            isr_base: args.isr_base,
            start_level: args.start_level,
            max_depth: args.max_depth,
            tau: args.tau,
            hisr_tile_level: args.hisr_tile_level,
        },
        splat_threshold: args.splat_threshold,
        reference_chunk: args.reference_chunk,
        ..RenderSettings::default()
    };
    eprintln!(
        "rendering {} ({} triangles) at {}x{}, rsm {}, method {} on {}",
        scene.name,
        scene.triangle_count(),
        args.width,
        args.height,
        args.rsm,
        args.method.name(),
        gpu.info.name
    );
    let mut renderer = Renderer::new(&gpu, &scene, &settings)?;
    if let Some(dir) = &args.sequence {
        return sequence(&args, &scene, &gpu, &mut renderer, dir);
    }
    renderer.update(&args.state_at(&scene, args.time))?;
    let frames = args.frames;
    let started = std::time::Instant::now();
    let mut line_open = false;
    let stats = renderer
        .render_frames(frames, |p| {
            if frames > 1 || p.submissions > 1 {
                eprint!("{}", progress_line(&p, started.elapsed().as_secs_f64()));
                line_open = p.frame < p.frames;
                if !line_open {
                    eprintln!();
                }
            }
        })
        .map_err(|e| {
            if line_open {
                eprintln!();
            }
            e.context("rendering failed; no output was written (existing files are untouched)")
        })?;
    let result = renderer.readback()?;
    // For --stats, the debug views and the timings JSON's light-patch numbers.
    let multires = renderer.readback_multires()?;
    let light_stats = match &multires {
        Some(m) => Some(crate::debug_view::light_patch_stats(
            m,
            renderer.isr_chosen_count()?,
        )),
        None => None,
    };
    let mut extra_views = Vec::new();
    for &view in &args.debug_view {
        let (what, rgba) = match (view, &multires) {
            (DebugView::Indirect, _) => continue,
            (_, None) => unreachable!("checked before rendering"),
            (DebugView::Levels, Some(m)) => (
                format!("patch level per pixel: {}", crate::debug_view::LEVEL_LEGEND),
                crate::debug_view::levels_png(m),
            ),
            (DebugView::VplCount, Some(m)) => {
                let (rgba, min, max) = crate::debug_view::vpl_count_png(m);
                (
                    format!("light patches evaluated per pixel, black {min} to white {max}"),
                    rgba,
                )
            }
        };
        extra_views.push((args.debug_view_path(view), what, rgba));
    }
    let total_area = renderer.multires().map(|m| m.total_area());
    drop(renderer);

    let r = args.report(&gpu, &scene, &stats);
    let mut r = r;
    r.light_patches = light_stats.clone();
    print!("{}", report::table(&r));
    if args.stats {
        match (&stats.patches_per_level, total_area, &light_stats) {
            (Some(counts), Some(area), Some(light)) => {
                print!("{}", report::patch_table(counts, area));
                println!("{light}");
            }
            _ => println!(
                "--stats: method {} has no multiresolution patches",
                args.method.name()
            ),
        }
    }
    if let Some(path) = &args.timings {
        report::write_json(path, &r)?;
        println!("wrote {}", path.display());
    }
    output::write_exr(&args.out, &result)?;
    output::write_png(&args.png, result.width, result.height, &result.display)?;
    println!("wrote {} and {}", args.out.display(), args.png.display());
    for (path, what, rgba) in extra_views {
        output::write_png(&path, result.width, result.height, &rgba)?;
        println!("wrote {} ({what})", path.display());
    }
    if args.debug_view.contains(&DebugView::Indirect) {
        let path = args.debug_view_path(DebugView::Indirect);
        let rgba = crate::debug_view::indirect_png(&result, args.exposure);
        output::write_png(&path, result.width, result.height, &rgba)?;
        println!(
            "wrote {} (indirect light alone: albedo/pi * E, exposure {})",
            path.display(),
            args.exposure
        );
    }

    gpu.validation_verdict()
}
