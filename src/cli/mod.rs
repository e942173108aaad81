//! The `isr` command line: argument parsing and the `render`, `devices` and
//! `export-builtin` commands. `main.rs` only calls [`run`].

use crate::output::OutputKind;
use crate::renderer::Renderer;
use crate::vk::Gpu;
use crate::{output, report, scene};
use anyhow::{bail, Context as _, Result};
use clap::{Args, Parser, Subcommand};
use options::{MethodArg, RunArgs};
use std::path::PathBuf;

mod interrupt;
mod options;
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

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    run: RunArgs,
    /// Frames to render; timings are medians over them (over all but the last,
    /// which alone counts fragments and invocations, when there are several).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=100_000), help_heading = "Size")]
    frames: u32,
    /// Multi-layer OpenEXR output (linear).
    #[arg(long, default_value = "out/render.exr", help_heading = "Output")]
    out: PathBuf,
    /// PNG output (tonemapped sRGB).
    #[arg(long, default_value = "out/render.png", help_heading = "Output")]
    png: PathBuf,
    /// Write per-pass GPU timings as JSON to this file.
    #[arg(long, help_heading = "Output")]
    timings: Option<PathBuf>,
    /// Print patch counts per level (also recorded in the timings JSON).
    #[arg(long, help_heading = "Output", hide_short_help = true)]
    stats: bool,
    /// Indirect samples per pixel for --method pathtrace.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=65536), help_heading = "--method pathtrace")]
    spp: u32,
    /// Random seed for --method pathtrace.
    #[arg(
        long,
        default_value_t = 1,
        help_heading = "--method pathtrace",
        hide_short_help = true
    )]
    seed: u64,
    /// Extra PNGs next to --png: `levels` colors each pixel by the level of its
    /// patch, `indirect` shows the indirect light alone, `vpl-count` is a heat
    /// map of the light patches evaluated per pixel. Repeatable.
    #[arg(long, value_enum, help_heading = "Output", hide_short_help = true)]
    debug_view: Vec<DebugView>,
    /// Write --frames frames at times --time + k / --fps into this folder
    /// (frame_0000.exr, frame_0000.png, ..., timings.json) instead of timing
    /// one frame --frames times.
    #[arg(long, help_heading = "Animation")]
    sequence: Option<PathBuf>,
    /// Frames per second of a --sequence.
    #[arg(
        long,
        default_value_t = 30.0,
        help_heading = "Animation",
        hide_short_help = true
    )]
    fps: f32,
    /// With --sequence, also write the frames as a looping animated GIF,
    /// DIR/sequence.gif, played at --fps.
    #[arg(
        long,
        requires = "sequence",
        help_heading = "Animation",
        hide_short_help = true
    )]
    gif: bool,
    /// Circle the light about the scene's vertical axis through its initial
    /// position, once per PERIOD seconds, still aimed at the same point.
    #[arg(long, value_name = "PERIOD", help_heading = "Animation")]
    orbit_light: Option<f32>,
    /// The same for the camera.
    #[arg(long, value_name = "PERIOD", help_heading = "Animation")]
    orbit_camera: Option<f32>,
}

impl RenderArgs {
    /// The scene's frame state at animation time `t`, with the built-in motion.
    fn state_at(&self, scene: &scene::Scene, t: f32) -> Result<scene::FrameState> {
        let mut state = scene.pose_at(t)?;
        let pivot = scene::motion::pivot(scene);
        if let Some(period) = self.orbit_light {
            scene::motion::orbit_light(&mut state, pivot, period, t);
        }
        if let Some(period) = self.orbit_camera {
            scene::motion::orbit_camera(&mut state, pivot, period, t);
        }
        Ok(state)
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
                width: self.run.width,
                height: self.run.height,
                rsm: self.run.rsm,
                method: self.run.method.name(),
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
        self.run.check_time()?;
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

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum DebugView {
    Levels,
    Indirect,
    VplCount,
}

/// Parses `std::env::args` and runs the command.
/// The `isr` command line as clap describes it: every command and option
/// (the docs' tests check guide.md against it).
pub fn command() -> clap::Command {
    <Cli as clap::CommandFactory>::command()
}

pub fn run() -> Result<()> {
    let cli = parse();
    interrupt::install()?;
    match cli.command {
        Command::Render(args) => render(*args),
        Command::Bench(args) => {
            interrupt::set_note(format!(
                "the rows finished are kept in {}; the same command resumes from them",
                args.out_dir.join(crate::bench::files::JOURNAL).display()
            ));
            crate::bench::cli(&args)
        }
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

/// The command line, with every numeric option of every command taking a
/// value that starts with a minus sign (`--exposure -inf`, `--time -1e-5`,
/// `--tau -.5`), which clap reads as options unless they are written as it
/// writes negative numbers: the option's own check then judges the value.
fn parse() -> Cli {
    use clap::{CommandFactory as _, FromArgMatches as _};
    let command = Cli::command().mut_subcommands(|c| c.mut_args(numeric_values_may_be_negative));
    Cli::from_arg_matches(&command.get_matches()).unwrap_or_else(|e| e.exit())
}

/// `arg`, taking values that start with '-' if its values are numbers.
fn numeric_values_may_be_negative(arg: clap::Arg) -> clap::Arg {
    use std::any::TypeId;
    let numeric = [
        TypeId::of::<f32>(),
        TypeId::of::<f64>(),
        TypeId::of::<u8>(),
        TypeId::of::<u16>(),
        TypeId::of::<u32>(),
        TypeId::of::<u64>(),
        TypeId::of::<usize>(),
        TypeId::of::<i32>(),
        TypeId::of::<i64>(),
        // The method parameters (`methods::args`).
        TypeId::of::<crate::settings::Value>(),
    ];
    let id = arg.get_value_parser().type_id();
    if numeric.iter().any(|t| id == *t) {
        arg.allow_hyphen_values(true)
    } else {
        arg
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
    let run = &args.run;
    let gpu_method = match run.method {
        MethodArg::Gpu(m) => Some(crate::methods::find(m)?),
        MethodArg::PathTrace => None,
    };
    let needs_multires = args
        .debug_view
        .iter()
        .any(|v| matches!(v, DebugView::Levels | DebugView::VplCount));
    if needs_multires && !gpu_method.is_some_and(|d| d.uses_multires()) {
        let with: Vec<&str> = crate::methods::REGISTRY
            .iter()
            .filter(|d| d.uses_multires())
            .map(|d| d.key().name())
            .collect();
        bail!(
            "--debug-view levels and vpl-count need a method with the multiresolution buffer \
             ({}); --method {} has none",
            with.join(", "),
            run.method.name()
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
    let scene = run.load_scene()?;
    let Some(descriptor) = gpu_method else {
        // Of the parameters, the path tracer reads the bounces alone.
        let bounces = crate::bounces::BOUNCES.name;
        for name in run.params.0 .0.keys().filter(|&&n| n != bounces) {
            eprintln!("warning: --method pathtrace does not read --{name}; it has no effect");
        }
        // The CPU reference renders the scene posed at --time.
        let state = args.state_at(&scene, run.time)?;
        return pathtrace(&args, &state.pose(&scene));
    };
    if scene
        .lights
        .iter()
        .any(|l| l.kind == scene::LightKind::Spot && l.outer_cone > crate::view::MAX_RSM_HALF_FOV)
    {
        eprintln!("warning: the spot cone is wider than the RSM's 80 degree half-angle; light beyond it is cut");
    }
    let settings = run.settings(descriptor.key());
    // The settings' own checks need no device: they fail before it starts.
    crate::frame::check::check_ranges(&settings)?;
    crate::methods::check(&settings)?;
    use crate::visibility::{unused_grid_warning, uses_voxels, Visibility, VISIBILITY};
    if let Some(w) = unused_grid_warning(&settings, uses_voxels(&settings)) {
        eprintln!("{w}");
    }
    for w in descriptor.warnings(&settings) {
        eprintln!("{w}");
    }
    let exact =
        descriptor.takes_exact_visibility() && VISIBILITY.get(&settings) == Visibility::Exact;
    if exact && args.sequence.is_some() {
        bail!("--visibility exact renders one frame (it is the CPU limit, minutes a frame); drop --sequence");
    }
    let gpu = Gpu::new(&run.gpu_options())?;
    eprintln!(
        "rendering {} ({} triangles) at {}x{}, rsm {}, method {} on {}",
        scene.name,
        scene.triangle_count(),
        run.width,
        run.height,
        run.rsm,
        run.method.name(),
        gpu.info.name
    );
    let mut renderer = Renderer::new(&gpu, &scene, &settings)?;
    if let Some(dir) = &args.sequence {
        return sequence(&args, &scene, &gpu, &mut renderer, dir);
    }
    let state = args.state_at(&scene, run.time)?;
    renderer.update(&state)?;
    let frames = args.frames;
    let mut bar: Option<indicatif::ProgressBar> = None;
    let mut finished = 0;
    let stats = renderer
        .render_frames(frames, |p| {
            finished = p.frame;
            if frames == 1 && p.submissions == 1 {
                return;
            }
            let bar = bar.get_or_insert_with(|| {
                crate::progress::bar((p.frames * p.submissions) as u64, "parts")
            });
            // A frame's completion is reported with submission 0, the parts
            // of a multi-submission frame with 1..submissions.
            bar.set_position((p.frame * p.submissions + p.submission) as u64);
            let part = match p.submissions {
                1 => String::new(),
                n => format!(", part {}/{n}", p.submission),
            };
            bar.set_message(format!(
                "frame {}/{}{part}",
                (p.frame + 1).min(p.frames),
                p.frames
            ));
        })
        .map_err(|e| {
            e.context(format!(
                "rendering failed after {finished} of {frames} frames; no output was written \
                 (existing files are untouched)"
            ))
        });
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let stats = stats?;
    let mut result = renderer.readback()?;
    if exact {
        // The indirect layer again on the CPU, each VPL tested for each pixel.
        let bar = crate::progress::bar(result.height as u64, "rows");
        bar.set_message("exact visibility");
        result = crate::exact_visibility::with_exact_visibility(
            &mut renderer,
            &state.pose(&scene),
            result,
            run.exposure,
            |done, _| bar.set_position(done as u64),
        )?;
        bar.finish_and_clear();
    }
    // For --stats, the debug views and the timings JSON's light-patch numbers.
    let multires = renderer.readback_multires()?;
    let light_stats = match &multires {
        Some(m) => Some(crate::debug_view::light_patch_stats(
            m,
            renderer.light_patches_chosen()?,
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
                run.method.name()
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
        let rgba = crate::debug_view::indirect_png(&result, run.exposure);
        output::write_png(&path, result.width, result.height, &rgba)?;
        println!(
            "wrote {} (indirect light alone: albedo/pi * E, exposure {})",
            path.display(),
            run.exposure
        );
    }

    gpu.validation_verdict()
}
