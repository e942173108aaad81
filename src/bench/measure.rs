//! Measuring one scene of a bench run, pass by pass (one per visibility,
//! `Plan::passes`): the pass's dense reference per frame, then every pending
//! sweep point of the pass against it and against the path-traced truth,
//! traced once per frame for every pass; each finished row is appended to
//! the journal.

use super::rows::{self, Row};
use super::sweep::Config;
use super::{flip, frame_time, gallery, metrics, truth_cache, Plan, SceneSpec};
use super::{visibility, REFERENCE, REFERENCE_LABEL};
use crate::bounces::Bounces;
use crate::readback::Readback;
use crate::renderer::{FrameStats, Renderer};
use crate::scene::Scene;
use crate::settings::{Method, RenderSettings};
use crate::visibility::Visibility;
use crate::vk::Gpu;
use anyhow::{Context as _, Result};
use std::collections::HashSet;
use std::path::Path;

/// One frame of a pass's dense reference, what its points are compared with.
struct RefFrame {
    indirect: Vec<[f32; 4]>,
    final_radiance: Vec<[f32; 4]>,
    mask: Vec<bool>,
    display: Vec<u8>,
}

/// One frame of the path-traced truth: its indirect image of the run's
/// bounces, the pixels it is compared on, and what the reference rows
/// report of it; with the bounces axis (`bounce_axis`), its images of 1, 2,
/// 3 and every bounce.
pub(super) struct TruthFrame {
    indirect: Vec<[f32; 4]>,
    pub(super) mask: Vec<bool>,
    spp: f64,
    noise: f64,
    left_out: f64,
    pub(super) axis: Vec<Vec<[f32; 4]>>,
}

impl TruthFrame {
    /// The frame of truth `t` whose rows are of `bounces` (`t`'s own, or
    /// fewer its layers hold: `Plan::truth_bounces`).
    pub(super) fn new(t: super::truth::Truth, bounces: Bounces) -> Result<TruthFrame> {
        let (indirect, noise) = t.of(bounces).with_context(|| {
            format!(
                "the truth of {} holds no truth of {}",
                t.bounces.words(),
                bounces.words()
            )
        })?;
        let axis = match t.bounces {
            Bounces::Infinite => super::bounce_axis::SUBJECT_BOUNCES
                .iter()
                .filter_map(|&b| t.of(b).map(|(x, _)| x))
                .collect(),
            _ => vec![],
        };
        Ok(TruthFrame {
            spp: t.spp as f64,
            noise,
            left_out: t.mask.left_out(),
            indirect,
            mask: t.mask.mask,
            axis,
        })
    }
}

/// The total the GPU allocator has handed out, in bytes.
fn allocated_bytes(gpu: &Gpu) -> Option<i64> {
    let a = gpu.shared.allocator.lock().ok()?;
    Some(a.generate_report().total_allocated_bytes as i64)
}

/// What a pass of a scene still needs.
pub(super) struct Pending {
    /// Points to measure (not in the journal).
    todo: Vec<Config>,
    /// Default points in the journal whose gallery images are missing.
    redraw: Vec<Config>,
    /// Whether the reference's row is to be written.
    ref_row: bool,
    /// Animation frames of the reference to render.
    ref_frames: u32,
}

impl Pending {
    /// What pass `plan` of `spec` needs that the journal (its keys, `done`)
    /// and the gallery's images lack; `None`: nothing.
    pub(super) fn of(plan: &Plan, spec: &SceneSpec, done: &HashSet<String>) -> Option<Pending> {
        let configs = plan.configs();
        let name = &spec.name;
        let is_done =
            |c: &Config| done.contains(&plan.key(name, c.method.name(), &c.label(&plan.base)));
        let todo: Vec<Config> = configs.iter().filter(|c| !is_done(c)).cloned().collect();
        let redraw: Vec<Config> = configs
            .iter()
            .filter(|c| is_done(c) && c.is_default(&plan.base))
            .filter(|c| !super::images_present(plan, spec, Some(c)))
            .cloned()
            .collect();
        let ref_row = !done.contains(&plan.key(name, REFERENCE.name(), REFERENCE_LABEL));
        let measures = ref_row || !todo.is_empty();
        if !measures && redraw.is_empty() && super::images_present(plan, spec, None) {
            return None;
        }
        // The reference's every frame where a point is measured; up to the
        // gallery's frame where only images are drawn again.
        let ref_frames = match measures {
            true => plan.frames,
            false => image_frames(plan),
        };
        Some(Pending {
            todo,
            redraw,
            ref_row,
            ref_frames,
        })
    }

    /// Whether it writes a row (and so needs the truth, where there is one).
    pub(super) fn measures(&self) -> bool {
        self.ref_row || !self.todo.is_empty()
    }

    /// Frames it renders (the progress bar's units), the truth's apart.
    pub(super) fn frames(&self, plan: &Plan) -> u64 {
        self.ref_frames as u64
            + plan.frames as u64 * self.todo.len() as u64
            + image_frames(plan) as u64 * self.redraw.len() as u64
    }
}

/// Frames up to the gallery's, the middle one.
fn image_frames(plan: &Plan) -> u32 {
    plan.frames / 2 + 1
}

/// Renders what `passes` of scene `spec` (`Plan::passes` with what each
/// needs) still need, then the bounces axis's `axis` (of scene plan
/// `plan`; `bounce_axis::pending`). Each frame's truth is traced, or read
/// from its cache, once, by the first pass that measures, and serves every
/// pass after it.
#[allow(clippy::too_many_arguments)]
pub(super) fn run_scene(
    gpu: &Gpu,
    plan: &Plan,
    spec: &SceneSpec,
    scene: &Scene,
    passes: &[(Plan, Pending)],
    axis: &[Vec<super::bounce_axis::Point>],
    journal: &Path,
    bar: &indicatif::ProgressBar,
) -> Result<()> {
    let frames = passes.iter().map(|(p, _)| p.frames).max().unwrap_or(0);
    let mut truths: Vec<Option<TruthFrame>> = (0..frames.max(plan.frames)).map(|_| None).collect();
    for (plan, work) in passes {
        let refs = reference(plan, gpu, spec, scene, work, &mut truths, journal, bar)?;
        points(plan, gpu, spec, scene, work, &refs, &truths, journal, bar)?;
    }
    super::bounce_axis::run(plan, gpu, spec, scene, axis, &mut truths, journal, bar)
}

/// The dense reference of pass `plan`, every frame it needs, with the truth
/// of each frame (traced where `truths` lacks it); its row where the
/// journal lacks it.
#[allow(clippy::too_many_arguments)]
fn reference(
    plan: &Plan,
    gpu: &Gpu,
    spec: &SceneSpec,
    scene: &Scene,
    work: &Pending,
    truths: &mut [Option<TruthFrame>],
    journal: &Path,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<RefFrame>> {
    let ref_row = work.ref_row;
    let images = super::files::images_dir(&plan.out_dir, &spec.name);
    let with_truth = plan.truth_noise.is_some() && work.measures();
    let name = visibility::series_name(crate::methods::REFERENCE.name(), &plan.visibility_label());
    let mut refs = Vec::with_capacity(plan.frames as usize);
    let mut ref_stats = FrameStats::default();
    let mut model = rows::TruthErrors::default();
    let settings = settings_of(plan, REFERENCE);
    let mut r = Renderer::new(gpu, scene, &settings)?;
    for k in 0..work.ref_frames {
        bar.set_message(format!(
            "{}: {name}, frame {}/{}",
            spec.name,
            k + 1,
            work.ref_frames
        ));
        let state = scene.pose_at(frame_time(spec, k))?;
        r.update(&state)?;
        let last = k + 1 == plan.frames;
        ref_stats.extend(r.render_frames_counting(1, last, |_| {})?);
        let out = r.readback()?;
        if with_truth {
            let posed = state.pose(scene);
            let slot = &mut truths[k as usize];
            let t = match slot.take() {
                Some(t) => slot.insert(t),
                None => {
                    let t = truth_cache::frame_truth(plan, spec, k, &posed, &r, &out, bar)?;
                    bar.inc(1);
                    slot.insert(TruthFrame::new(t, plan.bounces())?)
                }
            };
            // Only the reference's row without visibility keeps the floor:
            // minutes of rays when not cached, so not traced for a row
            // already measured.
            if ref_row && k == plan.frames / 2 && plan.visibility() == Visibility::None {
                let exact = truth_cache::model_floor(plan, spec, k, &posed, &mut r, &out, bar)?;
                model.floor = Some(metrics::relative_rmse(&exact, &t.indirect, &t.mask));
            }
            let n = plan.frames as f64;
            let e = metrics::relative_rmse(&out.indirect, &t.indirect, &t.mask);
            let add = |v: &mut Option<f64>, x: f64| *v = Some(v.unwrap_or(0.0) + x / n);
            add(&mut model.rel_rmse_indirect, e);
            add(&mut model.spp, t.spp);
            add(&mut model.noise, t.noise);
            add(&mut model.left_out, t.left_out);
        }
        if k == plan.frames / 2 {
            crate::output::write_png(
                &images.join(super::reference_image(plan)),
                out.width,
                out.height,
                &out.display,
            )?;
        }
        refs.push(RefFrame {
            mask: metrics::geometry_mask(&out.position),
            indirect: out.indirect,
            final_radiance: out.final_radiance,
            display: out.display,
        });
        bar.inc(1);
    }
    if ref_row {
        let mut row = timing_row(plan, spec, &settings, &ref_stats);
        row.label = REFERENCE_LABEL.into();
        row.key = plan.key(&spec.name, REFERENCE.name(), REFERENCE_LABEL);
        row.is_default = true;
        row.truth = model;
        rows::append(journal, &row)?;
    }
    Ok(refs)
}

/// Every point of pass `plan` still to measure or draw, against the pass's
/// reference `refs` and the truth `truths` of each frame.
#[allow(clippy::too_many_arguments)]
fn points(
    plan: &Plan,
    gpu: &Gpu,
    spec: &SceneSpec,
    scene: &Scene,
    work: &Pending,
    refs: &[RefFrame],
    truths: &[Option<TruthFrame>],
    journal: &Path,
    bar: &indicatif::ProgressBar,
) -> Result<()> {
    let images = super::files::images_dir(&plan.out_dir, &spec.name);
    let shown = plan.visibility_label();
    // The allocator's total without any indirect method, to subtract; and
    // without the grid, which is part of what visibility costs a method.
    let baseline = {
        let none = settings_of(plan, crate::methods::DIRECT_ONLY);
        let _none = Renderer::new(gpu, scene, &visibility::with(&none, Visibility::None))?;
        allocated_bytes(gpu)
    };
    let points = work.todo.iter().map(|c| (c, true));
    for (c, measure) in points.chain(work.redraw.iter().map(|c| (c, false))) {
        // A point drawn again for its images renders up to their frame.
        let frames = if measure {
            plan.frames
        } else {
            image_frames(plan)
        };
        let settings = c.settings(&plan.base);
        let label = c.label(&plan.base);
        let name = visibility::series_name(c.method.name(), &shown);
        let mut r = Renderer::new(gpu, scene, &settings)
            .with_context(|| format!("{name} {label} on {}", spec.name))?;
        let memory = match (allocated_bytes(gpu), baseline) {
            (Some(a), Some(b)) => Some(a - b),
            _ => None,
        };
        let mut stats = FrameStats::default();
        let mut flicker = metrics::Flicker::new(plan.base.width, plan.base.height);
        let mut flicker_final = metrics::Flicker::new(plan.base.width, plan.base.height);
        let (mut e_ind, mut e_fin, mut e_flip) = (0.0, 0.0, 0.0);
        let mut e_truth = None;
        let mut evals = None;
        for k in 0..frames {
            bar.set_message(format!(
                "{}: {name} {label}, frame {}/{frames}{}",
                spec.name,
                k + 1,
                if measure { "" } else { " (images only)" }
            ));
            r.update(&scene.pose_at(frame_time(spec, k))?)?;
            let n = if k == 0 && measure {
                plan.timing_frames
            } else {
                1
            };
            // Every frame times but the run's last, which counts (`Profiler`).
            let last = k + 1 == plan.frames;
            stats.extend(r.render_frames_counting(n, last, |_| {})?);
            let out = r.readback()?;
            let reference = &refs[k as usize];
            e_ind += metrics::relative_rmse(&out.indirect, &reference.indirect, &reference.mask);
            if let Some(t) = &truths[k as usize] {
                let e = metrics::relative_rmse(&out.indirect, &t.indirect, &t.mask);
                e_truth = Some(e_truth.unwrap_or(0.0) + e);
            }
            e_fin += metrics::relative_rmse(
                &out.final_radiance,
                &reference.final_radiance,
                &reference.mask,
            );
            let map = flip::flip_map(
                &reference.display,
                &out.display,
                out.width,
                out.height,
                flip::PIXELS_PER_DEGREE,
            )?;
            e_flip += flip::mean_flip(&map, &reference.mask);
            flicker.add(&out.indirect, &reference.indirect, &reference.mask)?;
            flicker_final.add(
                &out.final_radiance,
                &reference.final_radiance,
                &reference.mask,
            )?;
            if k + 1 == plan.frames {
                evals = light_patch_evals(&r, &settings, &out)?;
            }
            if k == plan.frames / 2 && c.is_default(&plan.base) {
                let [image, error] = super::point_images(plan, c);
                crate::output::write_png(&images.join(image), out.width, out.height, &out.display)?;
                crate::output::write_png(
                    &images.join(error),
                    out.width,
                    out.height,
                    &gallery::heat_map(&map),
                )?;
            }
            bar.inc(1);
        }
        if !measure {
            continue;
        }
        let f = plan.frames as f64;
        let mut row = timing_row(plan, spec, &settings, &stats);
        row.key = plan.key(&spec.name, c.method.name(), &label);
        row.label = label;
        row.is_default = c.is_default(&plan.base);
        row.rel_rmse_indirect = e_ind / f;
        row.rel_rmse_final = e_fin / f;
        row.truth.rel_rmse_indirect = e_truth.map(|e| e / f);
        row.flip = e_flip / f;
        row.flicker = flicker.flicker();
        row.flicker_second = flicker.second_difference();
        row.flicker_final = flicker_final.flicker();
        row.flicker_pixel = flicker.per_pixel();
        row.light_patch_evals = evals;
        row.gpu_memory_bytes = memory;
        if bar.is_hidden() {
            // No terminal (a log, CI): one line per finished row instead.
            eprintln!(
                "{}: {name} {}: {:.1} ms indirect, relative RMSE {:.4}",
                row.scene,
                row.label,
                row.indirect_ms.unwrap_or(f64::NAN),
                row.rel_rmse_indirect
            );
        }
        rows::append(journal, &row)?;
    }
    Ok(())
}

fn settings_of(plan: &Plan, method: Method) -> RenderSettings {
    RenderSettings {
        method,
        ..plan.base.clone()
    }
}

/// Light-patch evaluations of the last frame: counted by the multiresolution
/// gathers (and splats), or pixels with geometry times what the method
/// evaluates per pixel where that is fixed.
fn light_patch_evals(r: &Renderer, s: &RenderSettings, out: &Readback) -> Result<Option<u64>> {
    let d = crate::methods::find(s.method)?;
    if d.uses_multires() {
        return Ok(r
            .readback_multires()?
            .map(|m| crate::debug_view::light_patch_stats(&m, None).total_evaluations)
            .filter(|&n| n > 0));
    }
    Ok(d.evaluations_per_pixel(s).map(|n| {
        let pixels = out.position.iter().filter(|p| p[3] > 0.0).count() as u64;
        pixels * n
    }))
}

/// The values of every parameter `s`'s method reads, by name, as text.
fn parameter_values(s: &RenderSettings) -> std::collections::BTreeMap<String, String> {
    match crate::methods::find(s.method) {
        Ok(d) => crate::methods::params_of(d)
            .map(|p| (p.name().to_string(), p.text_in(s)))
            .collect(),
        Err(_) => Default::default(),
    }
}

/// A row with the settings and the timings filled in; errors zero.
pub(super) fn timing_row(
    plan: &Plan,
    spec: &SceneSpec,
    s: &RenderSettings,
    stats: &FrameStats,
) -> Row {
    let report = crate::report::build(
        &crate::report::RunInfo {
            device: "",
            driver: "",
            scene: &spec.name,
            width: s.width,
            height: s.height,
            rsm: s.rsm_resolution,
            method: s.method.name(),
        },
        stats,
    );
    let indirect_min = stats.gpu_ms_min(true);
    let fragments = stats.counts().map(|f| {
        f.iter()
            .filter(|p| p.kind.indirect)
            .filter_map(|p| p.fragment_invocations)
            .sum::<u64>()
    });
    Row {
        key: String::new(),
        scene: spec.name.clone(),
        method: s.method.name().into(),
        visibility: visibility::label(s),
        bounces: super::bounces::label(s),
        label: String::new(),
        is_default: false,
        params: parameter_values(s),
        width: s.width,
        height: s.height,
        rsm: s.rsm_resolution,
        frames: plan.frames,
        indirect_ms: report.indirect_gpu_ms_median,
        indirect_ms_min: indirect_min,
        total_ms: report.total_gpu_ms_median,
        passes: report
            .passes
            .iter()
            .filter_map(|p| Some((p.name.clone(), p.gpu_ms_median?)))
            .collect(),
        fragment_invocations: fragments,
        light_patch_evals: None,
        rel_rmse_indirect: 0.0,
        rel_rmse_final: 0.0,
        flip: 0.0,
        flicker: None,
        flicker_second: None,
        flicker_final: None,
        flicker_pixel: None,
        gpu_memory_bytes: None,
        truth: Default::default(),
    }
}
