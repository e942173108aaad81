//! `isr bench`: every method over its parameter sweep on the stress scenes,
//! against the dense reference of the same frame and the path-traced truth
//! (docs/algorithm.md section 6), written as `results.json`, `results.csv`, charts, a gallery and
//! `report.md` into one folder. Rows are journalled to `rows.jsonl` as they
//! finish, so an interrupted run resumes where it stopped.

pub mod bounce_axis;
pub mod bounces;
pub mod charts;
mod date;
pub mod files;
pub mod flip;
pub mod gallery;
pub mod headline;
mod measure;
pub mod metrics;
pub mod publish;
pub mod ratios;
pub mod report;
pub mod rows;
pub mod scenes;
mod shared_passes;
pub mod sweep;
pub mod truth;
mod truth_cache;
pub mod visibility;

use crate::bounces::BOUNCES;
use crate::scene::Scene;
use crate::settings::{Method, RenderSettings};
use crate::visibility::Visibility;
use crate::vk::{Gpu, GpuOptions};
use anyhow::{bail, Context as _, Result};
use measure::{run_scene, Pending};
use rows::Row;
use std::path::PathBuf;
use sweep::Config;

/// What `isr bench` runs (the CLI's flags; `cargo bench` fills it in code).
#[derive(clap::Args, Clone, Debug)]
pub struct BenchArgs {
    /// Scenes (comma-separated): bench scene names (see `scenes::SCENES`) or
    /// paths to .gltf/.glb/.obj files or scene descriptions (.scene.json).
    /// Default: all bench scenes (quick: cornell, slats).
    #[arg(long, value_delimiter = ',', num_args = 1..)]
    pub scenes: Vec<String>,
    /// Methods to sweep (comma-separated). Default: every method with a sweep
    /// (all but `none` and the references).
    #[arg(long, value_delimiter = ',', num_args = 1..)]
    pub methods: Vec<String>,
    /// Image width (default 128; quick 64).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height (default 128; quick 64).
    #[arg(long)]
    pub height: Option<u32>,
    /// RSM resolution (default 128; quick 64).
    #[arg(long)]
    pub rsm: Option<u32>,
    /// Animation frames per scene, 1/fps apart (default 6; quick 3).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Frames rendered for timing at the first animation frame (default 3; quick 2).
    #[arg(long)]
    pub timing_frames: Option<u32>,
    /// Where the results go; a run resumes from the rows already there.
    #[arg(long, default_value = "out/bench")]
    pub out_dir: PathBuf,
    /// The CI smoke test: two small scenes, a few settings per method, 64x64.
    #[arg(long)]
    pub quick: bool,
    /// The path-traced truth's noise target: samples are added until the
    /// relative RMSE of its Monte Carlo noise over the compared pixels is
    /// under this (default 0.02, about 15,000 samples per pixel on the
    /// stress scenes; quick 0.1). 0 traces no truth.
    #[arg(long)]
    pub truth_noise: Option<f64>,
    /// Indirect visibility (comma-separated): every method renders with
    /// `none`, and every method that reads visibility (the gathers, the
    /// splats, the dense reference; not lpv) again with each further entry,
    /// against a dense reference with the same visibility. `voxels`: the
    /// grid of --visibility-grid. Default: none,voxels (quick: none).
    /// `exact` is refused (CPU minutes a frame; `isr render --method
    /// reference --visibility exact`).
    #[arg(long, value_delimiter = ',', num_args = 1.., value_name = "none|voxels")]
    pub visibility: Vec<String>,
    /// Vulkan device index (`isr devices`).
    #[arg(long)]
    pub device: Option<usize>,
    /// After the run, publish it into the repository at ROOT: its report as
    /// ROOT/docs/results.md (charts, gallery and rows in ROOT/docs/results/)
    /// and its headline tables into ROOT/README.md, between the markers
    /// there (`--publish .` from the repository's root).
    #[arg(long, value_name = "ROOT")]
    pub publish: Option<PathBuf>,
    /// Parameters every point renders with, where its sweep does not set
    /// them (`--levels 4`: every multiresolution method at 4 levels).
    #[command(flatten)]
    pub params: crate::method_args::ParamArgsButVisibility,
}

impl Default for BenchArgs {
    fn default() -> Self {
        Self {
            scenes: vec![],
            methods: vec![],
            width: None,
            height: None,
            rsm: None,
            frames: None,
            timing_frames: None,
            out_dir: "out/bench".into(),
            quick: false,
            truth_noise: None,
            visibility: vec![],
            device: None,
            publish: None,
            params: Default::default(),
        }
    }
}

/// The resolved plan of a run.
#[derive(Clone, Debug)]
pub struct Plan {
    pub scenes: Vec<SceneSpec>,
    pub methods: Vec<Method>,
    pub base: RenderSettings,
    pub frames: u32,
    pub timing_frames: u32,
    pub quick: bool,
    pub out_dir: PathBuf,
    pub device: Option<usize>,
    /// The truth's noise target; `None`: no truth.
    pub truth_noise: Option<f64>,
    /// The visibility axis (`--visibility`; `visibility::parse`); a pass's
    /// plan (`Plan::passes`): its one visibility.
    pub visibilities: Vec<Visibility>,
    /// Whether the run measures the bounces axis (`bounce_axis::on`), and
    /// so traces the truth of every bounce at its frame (`Plan::truth_bounces`).
    pub bounce_axis: bool,
}

/// A scene of the run: its name, how it is made, its animation window, and
/// the size (image width = height, RSM) and frames it is benched at where
/// they are not the run's (the archive scenes', unless the command line
/// sets them).
#[derive(Clone, Debug)]
pub struct SceneSpec {
    pub name: String,
    pub file: Option<PathBuf>,
    pub start: f32,
    pub fps: f32,
    pub size: Option<(u32, u32)>,
    pub frames: Option<u32>,
}

impl SceneSpec {
    /// The scene, and a warning for each texture it shrinks to sample
    /// (`frame::texture_arrays`).
    fn load(&self) -> Result<Scene> {
        let scene = match &self.file {
            Some(p) => crate::scene::load_file(p, &Default::default())?,
            None => scenes::build(&self.name)?,
        };
        for w in crate::frame::texture_arrays::warnings(&scene.textures) {
            eprintln!("warning: {}: {w}", self.name);
        }
        Ok(scene)
    }
}

impl BenchArgs {
    /// Checks the flags and fills in the defaults; bad input is an error
    /// that names the valid values.
    pub fn plan(&self) -> Result<Plan> {
        let q = self.quick;
        let names: Vec<String> = if self.scenes.is_empty() {
            let d: &[&str] = if q {
                &["cornell", "slats"]
            } else {
                &["cornell", "fine", "hall", "slats", "moving-block"]
            };
            d.iter().map(|s| s.to_string()).collect()
        } else {
            self.scenes
                .iter()
                .flat_map(|n| match scenes::group(n) {
                    Some(g) => g.into_iter().map(str::to_string).collect(),
                    None => vec![n.clone()],
                })
                .collect()
        };
        let mut specs = vec![];
        for n in names {
            let lower = n.to_ascii_lowercase();
            if [".gltf", ".glb", ".obj", ".json"]
                .iter()
                .any(|e| lower.ends_with(e))
            {
                let path = PathBuf::from(&n);
                if !path.is_file() {
                    bail!("scene file {n} does not exist");
                }
                let name = path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or(n.clone());
                specs.push(SceneSpec {
                    name,
                    file: Some(path),
                    start: 0.0,
                    fps: 10.0,
                    size: None,
                    frames: None,
                });
            } else {
                let s = scenes::find(&n)?;
                // A scene's own size and frames yield to the command line's.
                let sized = self.width.is_none() && self.height.is_none() && self.rsm.is_none();
                specs.push(SceneSpec {
                    name: s.name.into(),
                    file: None,
                    start: s.start,
                    fps: s.fps,
                    size: s.size.filter(|_| sized && !q),
                    frames: s.frames.filter(|_| self.frames.is_none() && !q),
                });
            }
        }
        let swept = sweep::methods();
        let methods = if self.methods.is_empty() {
            swept
        } else {
            let mut chosen = vec![];
            for name in &self.methods {
                let m = crate::methods::by_name(name)?.key();
                if !swept.contains(&m) {
                    let valid: Vec<&str> = swept.iter().map(|m| m.name()).collect();
                    bail!(
                        "method '{name}' has no sweep (the dense reference renders once per scene and frame by itself); choose from: {}",
                        valid.join(", ")
                    );
                }
                chosen.push(m);
            }
            chosen
        };
        let small = if q { 64 } else { 128 };
        let (width, height) = (self.width.unwrap_or(small), self.height.unwrap_or(small));
        let rsm = self.rsm.unwrap_or(small);
        if !(8..=4096).contains(&width) || !(8..=4096).contains(&height) {
            bail!("--width and --height must be within 8..=4096 (got {width}x{height})");
        }
        if !rsm.is_power_of_two() || !(8..=4096).contains(&rsm) {
            bail!("--rsm {rsm}: the RSM resolution must be a power of two within 8..=4096");
        }
        let frames = self.frames.unwrap_or(if q { 3 } else { 6 });
        let timing_frames = self.timing_frames.unwrap_or(if q { 2 } else { 3 });
        if frames == 0 || frames > 1000 || timing_frames == 0 || timing_frames > 1000 {
            bail!("--frames and --timing-frames must be within 1..=1000");
        }
        let truth_noise = self
            .truth_noise
            .unwrap_or(if q { 0.1 } else { truth::NOISE_TARGET });
        if !(0.0..1.0).contains(&truth_noise) {
            bail!(
                "--truth-noise {truth_noise}: the path-traced truth's noise target must be at least 0 (no truth) and under 1; 0.02 is the default"
            );
        }
        let visibilities = visibility::parse(&self.visibility, q)?;
        let base = RenderSettings {
            width,
            height,
            rsm_resolution: rsm,
            params: self.params.0.clone(),
            ..RenderSettings::DEFAULT
        };
        let grid_used = visibilities.contains(&Visibility::Voxels);
        if let Some(w) = crate::visibility::unused_grid_warning(&base, grid_used) {
            eprintln!("{w}");
        }
        // Each pass sets its own (`Plan::passes`); a grid out of range is
        // refused before any work.
        let base = visibility::with(&base, Visibility::None);
        use crate::settings::params::AnyParam as _;
        if visibilities.contains(&Visibility::Voxels) {
            crate::voxel_grid::GRID.check(&base)?;
        }
        // The sweep's bounces: `--bounces` where given, else one, whatever
        // the renderer's default (the bounces axis measures the others
        // against the truth of every bounce, `bounce_axis`).
        let base = match BOUNCES.is_set_in(&base) {
            true => base,
            false => base.with(&BOUNCES, crate::bounces::Bounces::ONE),
        };
        // The truth's bounces, refused out of range before any work.
        crate::bounces::BOUNCES.check(&base)?;
        if let Some(w) = bounces::warning(&base, &methods).filter(|_| truth_noise > 0.0) {
            eprintln!("{w}");
        }
        let bounce_axis = bounce_axis::on(q, truth_noise > 0.0, BOUNCES.get(&base), &methods);
        Ok(Plan {
            scenes: specs,
            methods,
            base,
            frames,
            timing_frames,
            quick: q,
            out_dir: self.out_dir.clone(),
            device: self.device,
            truth_noise: (truth_noise > 0.0).then_some(truth_noise),
            visibilities,
            bounce_axis,
        })
    }
}

impl Plan {
    /// The plan of scene `s`: the run's, at the scene's own size and frames.
    pub fn for_scene(&self, s: &SceneSpec) -> Plan {
        let mut p = self.clone();
        if let Some((n, rsm)) = s.size {
            (p.base.width, p.base.height, p.base.rsm_resolution) = (n, n, rsm);
        }
        p.frames = s.frames.unwrap_or(p.frames);
        p
    }

    /// The sweep points of every method.
    pub fn configs(&self) -> Vec<Config> {
        self.methods
            .iter()
            .flat_map(|&m| sweep::sweep(m, self.base.rsm_resolution, self.quick))
            .collect()
    }

    /// The journal key of a row.
    pub fn key(&self, scene: &str, method: &str, label: &str) -> String {
        let b = &self.base;
        // The truth's noise too: its errors are part of the row; and the
        // flicker measure, so that rows of an older one are measured again.
        let truth = self
            .truth_noise
            .map_or("no truth".to_string(), |n| format!("truth noise {n}"));
        // With the voxel grid on (`--visibility voxels`), rows are kept
        // apart from a run's without it, so both can share a directory; so
        // are rows against a truth of more than one bounce.
        let visibility = match crate::visibility::uses_voxels(b) {
            true => format!("|{}", visibility::label(b)),
            false => String::new(),
        };
        format!(
            "{scene}|{method}|{label}|{}x{}|rsm {}|{} frames|{} timed|{truth}|flicker {}{visibility}{}",
            b.width,
            b.height,
            b.rsm_resolution,
            self.frames,
            self.timing_frames,
            metrics::FLICKER_MEASURE,
            bounces::key_suffix(b)
        )
    }

    /// Every key this run produces with its rows' visibility, in report
    /// order: per scene, each pass's reference and points.
    pub fn keys(&self) -> Vec<(String, String, bool)> {
        let mut keys = vec![];
        for s in &self.scenes {
            for p in self.for_scene(s).passes() {
                let v = p.visibility_label();
                let reference = p.key(&s.name, REFERENCE.name(), REFERENCE_LABEL);
                keys.push((reference, v.clone(), true));
                for c in p.configs() {
                    let k = p.key(&s.name, c.method.name(), &c.label(&p.base));
                    keys.push((k, v.clone(), c.is_default(&p.base)));
                }
            }
        }
        keys
    }
}

const REFERENCE_LABEL: &str = "every RSM texel";
const REFERENCE: Method = crate::methods::REFERENCE;

/// What a finished run returns (the rows of this plan, in order).
pub struct Outcome {
    pub rows: Vec<Row>,
    /// The rows of the bounces axis (`bounce_axis`), in its order.
    pub bounce_rows: Vec<Row>,
    pub device: String,
    pub driver: String,
    /// The command that ran (`isr bench ...`), and the day it finished
    /// (UTC, YYYY-MM-DD): what the published results name.
    pub command: String,
    pub date: String,
}

/// The images of `spec` that the gallery shows, written by
/// [`measure::run_scene`] at the middle animation frame for pass `plan`
/// (`Plan::passes`): the reference's and, per method with a default point,
/// that point's image and FLIP map.
fn gallery_images(plan: &Plan, spec: &SceneSpec) -> Vec<PathBuf> {
    let images = files::images_dir(&plan.out_dir, &spec.name);
    let mut files = vec![images.join(reference_image(plan))];
    for c in plan.configs().iter().filter(|c| c.is_default(&plan.base)) {
        files.extend(point_images(plan, c).map(|n| images.join(n)));
    }
    files
}

/// The gallery image of pass `plan`'s reference: `reference.png`, or with
/// the grid `reference-voxels.png`.
fn reference_image(plan: &Plan) -> String {
    files::image(crate::methods::REFERENCE.name(), plan.image_suffix())
}

/// The gallery images of point `c` of pass `plan`, its image and its FLIP
/// map: `hisr.png` and `hisr-error.png`, or `hisr-voxels.png` ...
fn point_images(plan: &Plan, c: &Config) -> [String; 2] {
    let (m, v) = (c.method.name(), plan.image_suffix());
    [files::image(m, v), files::error_map(m, v)]
}

/// Whether the gallery images of point `c` of `spec` (or, without one, the
/// reference's) are all there.
fn images_present(plan: &Plan, spec: &SceneSpec, c: Option<&Config>) -> bool {
    let images = files::images_dir(&plan.out_dir, &spec.name);
    let names = match c {
        None => vec![reference_image(plan)],
        Some(c) => point_images(plan, c).to_vec(),
    };
    names.iter().all(|n| images.join(n).is_file())
}

/// Checks, before any work, every file the run reads or writes in its
/// folder as `isr render` checks its outputs (`output::check_output`):
/// regular files only (a link is followed to its target), their folders
/// creatable and writable. A link to `/dev/null` or a FIFO named
/// `rows.jsonl` is refused by name instead of failing mid-run or waiting
/// for ever.
fn check_outputs(plan: &Plan) -> Result<()> {
    let dir = &plan.out_dir;
    let remedy = format!(
        "remove it, or choose another --out-dir than {}",
        dir.display()
    );
    let mut files: Vec<PathBuf> = std::iter::once(files::JOURNAL.to_string())
        .chain(files::written())
        .map(|n| dir.join(n))
        .collect();
    for s in &plan.scenes {
        for p in plan.for_scene(s).passes() {
            files.extend(gallery_images(&p, s));
        }
    }
    for f in files {
        crate::output::check_output("bench output", &f, Some(&remedy))?;
    }
    Ok(())
}

/// Runs the plan: renders what the journal lacks, then writes every output.
/// A point whose row is in the journal but whose gallery images are missing
/// is rendered again for the images alone; its row stays as measured.
pub fn run(plan: &Plan) -> Result<Outcome> {
    let dir = &plan.out_dir;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let journal = dir.join(files::JOURNAL);
    check_outputs(plan)?;
    let found = rows::read_journal(&journal)?;
    for w in found.warnings(&journal) {
        eprintln!("{w}");
    }
    let done = rows::done_keys(&found.rows);
    let gpu = Gpu::new(&GpuOptions {
        device_index: plan.device,
        ..Default::default()
    })?;
    crate::bench::charts::register_font();
    // Work units: one per frame rendered (each pass's reference and every
    // pending point) and per frame traced (the truth, once per scene).
    #[allow(clippy::type_complexity)]
    let mut pending: Vec<(
        SceneSpec,
        Plan,
        Vec<(Plan, Pending)>,
        Vec<Vec<bounce_axis::Point>>,
    )> = vec![];
    let mut units = 0u64;
    for s in &plan.scenes {
        let scene_plan = plan.for_scene(s);
        let passes: Vec<(Plan, Pending)> = scene_plan
            .passes()
            .into_iter()
            .filter_map(|p| Pending::of(&p, s, &done).map(|w| (p, w)))
            .collect();
        let axis = bounce_axis::pending(&scene_plan, s, &done);
        if passes.is_empty() && axis.is_empty() {
            continue;
        }
        let measures = passes.iter().any(|(_, w)| w.measures()) || !axis.is_empty();
        if scene_plan.truth_noise.is_some() && measures {
            units += scene_plan.frames as u64;
        }
        units += passes.iter().map(|(p, w)| w.frames(p)).sum::<u64>();
        let axis_frames = scene_plan.axis_frame() as u64 + 1;
        units += axis.iter().map(|m| m.len() as u64).sum::<u64>() * axis_frames;
        pending.push((s.clone(), scene_plan, passes, axis));
    }
    let bar = crate::progress::bar(units, "frames");
    for (spec, scene_plan, passes, axis) in &pending {
        let scene = spec.load()?;
        run_scene(&gpu, scene_plan, spec, &scene, passes, axis, &journal, &bar)?;
    }
    bar.finish_and_clear();
    let all = rows::read_journal(&journal)?.rows;
    // Rows journalled before the axis have no visibility: their key's. A
    // row is its method's default by today's defaults, not by those of the
    // run that journalled it (a resumed run after a default moved).
    let rows: Vec<Row> = plan
        .keys()
        .into_iter()
        .filter_map(|(k, visibility, is_default)| {
            let r = all.iter().rev().find(|r| r.key == k).cloned()?;
            Some(Row {
                visibility,
                is_default,
                ..r
            })
        })
        .collect();
    let bounce_rows: Vec<Row> = bounce_axis::keys(plan)
        .into_iter()
        .filter_map(|k| all.iter().rev().find(|r| r.key == k).cloned())
        .collect();
    let outcome = Outcome {
        rows,
        bounce_rows,
        device: gpu.info.name.clone(),
        driver: gpu.info.driver.clone(),
        command: command_line(),
        date: date::today(),
    };
    report::write_all(plan, &outcome)?;
    Ok(outcome)
}

/// `isr bench`: plans, runs, prints where the results are and the ratios.
pub fn cli(args: &BenchArgs) -> Result<()> {
    let plan = args.plan()?;
    if let Some(root) = &args.publish {
        // Checked before the run, not after an hour of it.
        let readme = std::fs::read_to_string(root.join("README.md")).map_err(|e| {
            anyhow::anyhow!(
                "--publish {}: no README.md to publish into ({e})",
                root.display()
            )
        })?;
        if publish::block(&readme).is_none() {
            bail!(
                "--publish {}: README.md has no block between {} and {} for the headline tables",
                root.display(),
                publish::BEGIN,
                publish::END
            );
        }
    }
    let outcome = run(&plan)?;
    println!("{}", ratios::ratios_text(&ratios::ratios(&outcome.rows)));
    println!("wrote {} to {}", files::summary(), plan.out_dir.display());
    if let Some(root) = &args.publish {
        publish::publish(&plan, &outcome, root)?;
    }
    Ok(())
}

/// The command line this process was started with, as `isr bench ...`.
fn command_line() -> String {
    let args: Vec<String> = std::env::args().skip(1).collect();
    format!("isr {}", args.join(" "))
}

/// Animation time of frame `k`.
fn frame_time(spec: &SceneSpec, k: u32) -> f32 {
    spec.start + k as f32 / spec.fps
}
