//! The bench's bounces axis (docs/algorithm.md section 6.6, "Bounces"): in a
//! run of one bounce (no `--bounces`) with a truth, every method that
//! renders bounces (`Descriptor::renders_bounces`) renders again at its
//! default point and the default visibility with bounces 1 and `inf` (the
//! subject with 1, 2, 3 and `inf`: the candidates of its default), each
//! measured against the truth of every bounce, and its extra light (the
//! light bounces 2..N add, `I_N - I_1`) against what they add in the truth
//! (`T_N - T_1`), at the middle animation frame (`Plan::axis_frame`; the
//! frames before it rendered, for what carries over between frames). The
//! truth of every bounce is that frame's one trace: its layers by bounce
//! hold the truth of one bounce the other rows are measured against
//! (`Plan::truth_bounces`), so nothing is traced twice, and the other
//! frames' truths stay of one bounce (the truth of every bounce took 3.4x
//! as long on the box).
//! Its rows are apart from the others (`Outcome::bounce_rows`, their own
//! keys): the run's tables and charts stay of one bounce.

use super::measure::{timing_row, TruthFrame};
use super::rows::{self, Row};
use super::sweep::Config;
use super::{frame_time, truth_cache, visibility, Plan, SceneSpec};
use crate::bounces::{Bounces, BOUNCES};
use crate::renderer::{FrameStats, Renderer};
use crate::scene::Scene;
use crate::settings::{Method, ParamType as _};
use crate::visibility::VISIBILITY;
use crate::vk::Gpu;
use anyhow::{Context as _, Result};
use std::collections::HashSet;
use std::path::Path;

/// The bounces the subject renders on the axis: the candidates of its
/// default. Every bounce (`inf`) is last, the truth the axis is held to.
pub const SUBJECT_BOUNCES: [Bounces; 4] = [
    Bounces::ONE,
    Bounces::Count(2),
    Bounces::Count(3),
    Bounces::Infinite,
];
/// The bounces every other method renders on the axis: one and every.
pub const OTHER_BOUNCES: [Bounces; 2] = [Bounces::ONE, Bounces::Infinite];

/// The bounces `method` renders on the axis.
pub fn bounces_of(method: Method) -> &'static [Bounces] {
    match method == crate::methods::SUBJECT {
        true => &SUBJECT_BOUNCES,
        false => &OTHER_BOUNCES,
    }
}

/// The methods of `methods` on the axis: those that render bounces.
pub fn methods(methods: &[Method]) -> Vec<Method> {
    let renders = |m: &Method| crate::methods::find(*m).is_ok_and(|d| d.renders_bounces());
    methods.iter().copied().filter(renders).collect()
}

/// Whether a run of `bounces` with `methods` measures the axis: a full
/// run (not `--quick`, the smoke test) of one bounce with a truth and a
/// method that renders bounces.
pub fn on(quick: bool, truth: bool, bounces: Bounces, list: &[Method]) -> bool {
    !quick && truth && bounces == Bounces::ONE && !methods(list).is_empty()
}

impl Plan {
    /// The frame the axis is measured at: the middle one (as the model's
    /// floor is), so that only its truth is of every bounce.
    pub fn axis_frame(&self) -> u32 {
        self.frames / 2
    }

    /// The bounces of the truth this plan traces at frame `k`: every
    /// bounce at the axis's frame where it measures the axis (its first
    /// layer is the truth of one), else `--bounces`.
    pub fn truth_bounces(&self, k: u32) -> Bounces {
        match self.bounce_axis && k == self.axis_frame() {
            true => Bounces::Infinite,
            false => self.bounces(),
        }
    }

    /// The axis's plan: the run's at the default visibility.
    fn axis_plan(&self) -> Plan {
        let v = VISIBILITY.default_in(&self.base);
        Plan {
            base: visibility::with(&self.base, v),
            ..self.clone()
        }
    }
}

/// One point of the axis: a method's default point at the default
/// visibility, with `bounces`.
#[derive(Clone, Debug)]
pub struct Point {
    pub config: Config,
    pub bounces: Bounces,
}

/// The axis's points of scene plan `plan` (`Plan::for_scene`), per method
/// in the run's order, each method's bounces in [`bounces_of`]'s order.
pub fn points(plan: &Plan) -> Vec<Point> {
    if !plan.bounce_axis {
        return vec![];
    }
    let axis = plan.axis_plan();
    let mut out = vec![];
    for m in methods(&plan.methods) {
        let sweep = super::sweep::sweep(m, axis.base.rsm_resolution, axis.quick);
        let Some(c) = sweep.into_iter().find(|c| c.is_default(&axis.base)) else {
            continue;
        };
        for &bounces in bounces_of(m) {
            out.push(Point {
                config: c.clone(),
                bounces,
            });
        }
    }
    out
}

/// The journal key of `p` in scene `scene` of `plan`: the row's at the
/// default visibility, with `|bounce axis N`.
pub fn key(plan: &Plan, scene: &str, p: &Point) -> String {
    let axis = plan.axis_plan();
    let label = p.config.label(&axis.base);
    let k = axis.key(scene, p.config.method.name(), &label);
    format!("{k}|bounce axis {}", p.bounces.text())
}

/// Every key of the axis of the run `plan`, in report order.
pub fn keys(plan: &Plan) -> Vec<String> {
    let mut out = vec![];
    for s in &plan.scenes {
        let p = plan.for_scene(s);
        out.extend(points(&p).iter().map(|pt| key(&p, &s.name, pt)));
    }
    out
}

/// The methods of scene plan `plan` whose axis rows the journal (its keys,
/// `done`) lacks: a method's rows are measured together, as its rows of
/// N bounces measure their extra light against its row of one.
pub fn pending(plan: &Plan, spec: &SceneSpec, done: &HashSet<String>) -> Vec<Vec<Point>> {
    let mut out: Vec<Vec<Point>> = vec![];
    for p in points(plan) {
        match out.last_mut() {
            Some(l) if l[0].config.method == p.config.method => l.push(p),
            _ => out.push(vec![p]),
        }
    }
    out.retain(|l| l.iter().any(|p| !done.contains(&key(plan, &spec.name, p))));
    out
}

/// The sum of the light (r + g + b) of `x` over `mask`.
fn light(x: &[[f32; 4]], mask: &[bool]) -> f64 {
    x.iter()
        .zip(mask)
        .filter(|(_, m)| **m)
        .map(|(p, _)| (p[0] + p[1] + p[2]) as f64)
        .sum()
}

/// The share of the indirect light of bounces 1, 2, 3 and 4 and on in the
/// truths of 1, 2, 3 and every bounce (`truths`, cumulative) over `mask`.
pub fn shares(truths: &[Vec<[f32; 4]>], mask: &[bool]) -> Vec<f64> {
    let sums: Vec<f64> = truths.iter().map(|t| light(t, mask)).collect();
    let all = sums.last().copied().unwrap_or(0.0).max(1e-30);
    let mut before = 0.0;
    sums.iter()
        .map(|&s| {
            let share = (s - before) / all;
            before = s;
            share
        })
        .collect()
}

/// Renders the axis's `work` (`pending`) of scene `spec` up to its frame
/// and journals its rows. `truths`: each frame's; the axis frame's is
/// traced where missing (by the first method).
#[allow(clippy::too_many_arguments)]
pub(super) fn run(
    plan: &Plan,
    gpu: &Gpu,
    spec: &SceneSpec,
    scene: &Scene,
    work: &[Vec<Point>],
    truths: &mut [Option<TruthFrame>],
    journal: &Path,
    bar: &indicatif::ProgressBar,
) -> Result<()> {
    let axis = plan.axis_plan();
    for points in work {
        // The method's image of one bounce at the axis's frame: what its
        // extra light is measured from.
        let mut one: Option<Vec<[f32; 4]>> = None;
        for p in points {
            let mut s = p.config.settings(&axis.base);
            BOUNCES.set(&mut s, p.bounces);
            let label = p.config.label(&axis.base);
            let name = format!("{} {label}, {}", p.config.method.name(), p.bounces.words());
            let mut r = Renderer::new(gpu, scene, &s)
                .with_context(|| format!("{name} on {}", spec.name))?;
            let mut stats = FrameStats::default();
            let (mut e_all, mut e_same) = (0.0, 0.0);
            let (mut extra, mut extra_truth) = (0.0, 0.0);
            let mut share = vec![];
            let at = axis.axis_frame();
            for k in 0..=at {
                bar.set_message(format!("{}: {name}, frame {}/{}", spec.name, k + 1, at + 1));
                let state = scene.pose_at(frame_time(spec, k))?;
                r.update(&state)?;
                let n = if k == 0 { axis.timing_frames } else { 1 };
                stats.extend(r.render_frames_counting(n, k == at, |_| {})?);
                bar.inc(1);
                if k < at {
                    continue;
                }
                let out = r.readback()?;
                let slot = &mut truths[k as usize];
                if slot.is_none() {
                    let posed = state.pose(scene);
                    let t = truth_cache::frame_truth(&axis, spec, k, &posed, &r, &out, bar)?;
                    *slot = Some(TruthFrame::new(t, axis.bounces())?);
                }
                let t = slot.as_ref().expect("filled above");
                let [t1, .., every] = &t.axis[..] else {
                    anyhow::bail!(
                        "{}: the truth of frame {k} has no layers by bounce",
                        spec.name
                    );
                };
                let same = match p.bounces {
                    Bounces::Infinite => every,
                    b => &t.axis[b.layers() - 1],
                };
                e_all = super::metrics::relative_rmse(&out.indirect, every, &t.mask);
                e_same = super::metrics::relative_rmse(&out.indirect, same, &t.mask);
                if p.bounces == Bounces::ONE {
                    one = Some(out.indirect.clone());
                } else if let Some(i1) = &one {
                    extra = light(&out.indirect, &t.mask) - light(i1, &t.mask);
                    extra_truth = light(same, &t.mask) - light(t1, &t.mask);
                }
                share = shares(&t.axis, &t.mask);
            }
            let mut row = timing_row(&axis, spec, &s, &stats);
            row.key = key(plan, &spec.name, p);
            row.label = label;
            row.is_default = true;
            row.frames = at + 1;
            row.truth.rel_rmse_indirect = Some(e_all);
            row.truth.same_bounces = Some(e_same);
            row.truth.extra_light =
                (p.bounces != Bounces::ONE && extra_truth.abs() > 0.0).then(|| extra / extra_truth);
            row.truth.shares = Some(share);
            if bar.is_hidden() {
                eprintln!(
                    "{}: {name}: {:.1} ms indirect, relative RMSE against every bounce {:.4}",
                    spec.name,
                    row.indirect_ms.unwrap_or(f64::NAN),
                    e_all
                );
            }
            rows::append(journal, &row)?;
        }
    }
    Ok(())
}

/// The subject's axis rows of `rows` as settings of one knob, their
/// bounces (label `1`, `2`, `3`, `inf`), for `headline::best_balance`.
fn as_settings(rows: &[Row]) -> Vec<Row> {
    let subject = crate::methods::SUBJECT.name();
    rows.iter()
        .filter(|r| r.method == subject)
        .map(|r| Row {
            label: r.bounces.clone(),
            ..r.clone()
        })
        .collect()
}

/// The subject's default bounces by the best-balance rule
/// (`headline::best_balance`): the cheapest bounces whose error against
/// the truth of every bounce, on the bench scenes, is within
/// `headline::BALANCE` of the lowest; with every bounces setting measured.
pub fn default_bounces(
    rows: &[Row],
) -> (
    Option<super::headline::Setting>,
    Vec<super::headline::Setting>,
) {
    let rows = as_settings(rows);
    let subject = crate::methods::SUBJECT.name();
    (
        super::headline::best_balance(&rows, subject),
        super::headline::settings(&rows, subject),
    )
}

/// The bounce passes' median ms in `r` (`bounce-*`), by name.
fn bounce_passes(r: &Row) -> String {
    let passes: Vec<String> = r
        .passes
        .iter()
        .filter(|(n, _)| n.starts_with("bounce"))
        .map(|(n, ms)| format!("{n} {ms:.1}"))
        .collect();
    match passes.is_empty() {
        true => "-".into(),
        false => passes.join(", "),
    }
}

/// `report.md`'s sections of the axis (empty without its rows): each
/// scene's share of the truth's indirect light per bounce; every axis row's
/// errors, extra light and cost; the subject's default bounces by the rule.
pub fn report(rows: &[Row]) -> String {
    if rows.is_empty() {
        return String::new();
    }
    let f4 = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.4}"));
    let mut md = "\n## Bounces\n\nThe truth of every bounce is traced once, at the axis's frame; its layers by bounce \
give the truth of 1, 2 and 3 bounces (docs/algorithm.md section 6.6); the axis is measured at the \
middle animation frame, the frames before it rendered. Each scene's share of the truth's indirect light \
per bounce (over the compared pixels):\n\n\
| scene | bounce 1 | bounce 2 | bounce 3 | bounces 4 and on |\n| --- | ---: | ---: | ---: | ---: |\n"
        .to_string();
    let mut scenes: Vec<&str> = vec![];
    for r in rows {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    for s in &scenes {
        let Some(shares) = rows
            .iter()
            .find(|r| r.scene == *s)
            .and_then(|r| r.truth.shares.clone())
        else {
            continue;
        };
        md += &format!("| {s} |");
        for v in shares {
            md += &format!(" {:.1}% |", 100.0 * v);
        }
        md += "\n";
    }
    md += "\nEach method that renders bounces, at its default point and visibility, with each bounces \
setting (section 5.9): relative RMSE of the indirect image against the truth of every bounce and \
against the truth of its own bounces, over the pixels away from geometric and shadow edges (the truth's \
mask); the light its bounces 2..N add over what they add in the truth \
(`(I_N - I_1) / (T_N - T_1)`, summed over the compared pixels; 1: as much); the median \
indirect ms and, in it, the bounce passes' median ms each.\n\n\
| scene | method | setting | bounces | RMSE every bounce | RMSE own bounces | extra light | indirect ms | bounce passes (ms) |\n\
| --- | --- | --- | --- | ---: | ---: | ---: | ---: | --- |\n";
    for r in rows {
        md += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.scene,
            r.method,
            visibility::series_name(&r.label, &r.visibility),
            r.bounces,
            f4(r.truth.rel_rmse_indirect),
            f4(r.truth.same_bounces),
            r.truth
                .extra_light
                .map_or("-".into(), |v| format!("{v:.2}")),
            r.indirect_ms.map_or("-".into(), |v| format!("{v:.1}")),
            bounce_passes(r)
        );
    }
    let (best, mut all) = default_bounces(rows);
    if all.is_empty() {
        return md;
    }
    let subject = crate::methods::SUBJECT.name();
    all.sort_by(|a, b| a.total_ms.total_cmp(&b.total_ms));
    md += &format!(
        "\nThe default bounces, by the best-balance rule: the cheapest bounces setting of `{subject}` \
(indirect time summed over the scenes) whose error against the truth of every bounce (the mean over the \
scenes of its error relative to the lowest any bounces setting reaches there) is within {}x of the \
lowest. Every setting, cheapest first:\n\n| bounces | error (x the lowest) | indirect ms, summed |\n\
| --- | ---: | ---: |\n",
        super::headline::BALANCE
    );
    for s in &all {
        let within = s.relative_error <= super::headline::BALANCE;
        md += &format!(
            "| {}{} | {:.2} | {:.1} |\n",
            s.label,
            if within { " (within)" } else { "" },
            s.relative_error,
            s.total_ms
        );
    }
    if let Some(b) = best {
        md += &format!("\nThe rule picks `--bounces {}`.\n", b.label);
    }
    md
}

/// The headline's table of the axis (empty without its rows): per method
/// and scene, the error against the truth of every bounce with one bounce
/// and with every bounce, and the indirect ms with every bounce.
pub fn headline(rows: &[Row]) -> String {
    let (one, every) = (Bounces::ONE.text(), Bounces::Infinite.text());
    let (mut methods, mut scenes): (Vec<&str>, Vec<&str>) = (vec![], vec![]);
    for r in rows {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    if methods.is_empty() {
        return String::new();
    }
    let default = BOUNCES
        .get(&crate::settings::RenderSettings::DEFAULT)
        .text();
    let mut md = format!(
        "\nEvery bounce (the bounces axis, at the middle animation frame, each method at its default with \
the grid): the relative RMSE of the indirect image against the path-traced truth of every bounce, over the \
pixels away from geometric and shadow edges, with one bounce, then with every bounce (`--bounces inf`); and the indirect time with every bounce. The default, \
`--bounces {default}`, is the best balance of `hisr`'s settings (docs/results.md, \"Bounces\").\n\n| method |"
    );
    for s in &scenes {
        md += &format!(" `{s}` |");
    }
    md += "\n| --- |";
    md += &" ---: |".repeat(scenes.len());
    md += "\n";
    let err = |r: Option<&Row>| {
        r.and_then(|r| r.truth.rel_rmse_indirect)
            .map_or("-".into(), |e| format!("{e:.3}"))
    };
    for m in &methods {
        md += &format!("| `{m}` |");
        for s in &scenes {
            let of = |b: &str| {
                rows.iter()
                    .find(|r| r.method == *m && r.scene == *s && r.bounces == b)
            };
            let ms = of(&every)
                .and_then(|r| r.indirect_ms)
                .map_or("-".into(), super::headline::ms);
            md += &format!(" {} -> {}, {ms} |", err(of(&one)), err(of(&every)));
        }
        md += "\n";
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(scene: &str, bounces: &str, ms: f64, err: f64) -> Row {
        let mut r = super::super::rows::tests_support::row(scene);
        r.scene = scene.into();
        r.method = crate::methods::SUBJECT.name().into();
        r.label = "default".into();
        r.visibility = "voxels 64".into();
        r.bounces = bounces.into();
        r.indirect_ms = Some(ms);
        r.truth.rel_rmse_indirect = Some(err);
        r
    }

    #[test]
    fn the_default_bounces_are_the_cheapest_within_reach_of_the_lowest_error() {
        let mut rows = vec![
            // One bounce: twice the lowest error on s1, cheap.
            row("s1", "1", 10.0, 0.40),
            row("s2", "1", 10.0, 0.30),
            // Two: 1.1x and 1.2x the lowest, mean 1.15: within.
            row("s1", "2", 15.0, 0.22),
            row("s2", "2", 15.0, 0.24),
            // Every bounce: the lowest, the dearest.
            row("s1", "inf", 30.0, 0.20),
            row("s2", "inf", 30.0, 0.20),
        ];
        // Another method's rows do not count.
        let mut other = row("s1", "1", 1.0, 0.01);
        other.method = "other".into();
        rows.push(other);
        let (best, all) = default_bounces(&rows);
        let best = best.unwrap();
        assert_eq!(best.label, "2");
        assert!((best.relative_error - 1.15).abs() < 1e-12);
        assert_eq!(best.total_ms, 30.0);
        assert_eq!(all.len(), 3);
        // One bounce within reach everywhere: the rule keeps it.
        rows[0].truth.rel_rmse_indirect = Some(0.21);
        rows[1].truth.rel_rmse_indirect = Some(0.21);
        assert_eq!(default_bounces(&rows).0.unwrap().label, "1");
        let md = report(&rows);
        assert!(md.contains("The rule picks `--bounces 1`"), "{md}");
        assert!(report(&[]).is_empty());
    }

    #[test]
    fn shares_split_the_light_of_every_bounce_by_bounce() {
        let img = |v: f32| vec![[v, v, v, 1.0], [v, v, v, 1.0], [100.0; 4]];
        let mask = [true, true, false];
        // Cumulative truths of 1, 2, 3 and every bounce: 0.5, 0.75, 0.875, 1.
        let truths = [img(0.5), img(0.75), img(0.875), img(1.0)];
        let s = shares(&truths, &mask);
        assert_eq!(s.len(), 4);
        for (got, want) in s.iter().zip([0.5, 0.25, 0.125, 0.125]) {
            assert!((got - want).abs() < 1e-6, "{s:?}");
        }
        assert!((s.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        // No light at all: no share, rather than a division by zero.
        assert!(shares(&[img(0.0), img(0.0)], &mask)
            .iter()
            .all(|v| *v == 0.0));
    }

    #[test]
    fn the_axis_is_on_for_full_runs_of_one_bounce_with_a_truth_and_a_method_that_renders_bounces() {
        let hisr = [crate::methods::SUBJECT];
        assert!(on(false, true, Bounces::ONE, &hisr));
        assert!(!on(true, true, Bounces::ONE, &hisr));
        assert!(!on(false, false, Bounces::ONE, &hisr));
        assert!(!on(false, true, Bounces::Infinite, &hisr));
        assert!(!on(
            false,
            true,
            Bounces::ONE,
            &[crate::methods::DIRECT_ONLY]
        ));
        assert_eq!(bounces_of(crate::methods::SUBJECT).len(), 4);
        assert_eq!(
            *bounces_of(crate::methods::SUBJECT).last().unwrap(),
            Bounces::Infinite
        );
    }

    #[test]
    fn only_the_axis_frame_traces_every_bounce_and_the_subject_has_four_points() {
        let args = |quick| crate::bench::BenchArgs {
            scenes: vec!["cornell".into()],
            methods: vec!["hisr".into(), "lpv".into()],
            frames: Some(6),
            quick,
            ..Default::default()
        };
        let plan = args(false).plan().unwrap();
        assert!(plan.bounce_axis);
        assert_eq!(plan.axis_frame(), 3);
        for k in 0..6 {
            let b = if k == 3 {
                Bounces::Infinite
            } else {
                Bounces::ONE
            };
            assert_eq!(plan.truth_bounces(k), b, "frame {k}");
        }
        // lpv renders one bounce: not on the axis.
        let scene = plan.for_scene(&plan.scenes[0]);
        let got: Vec<Bounces> = points(&scene).iter().map(|p| p.bounces).collect();
        assert_eq!(got, SUBJECT_BOUNCES);
        let k = key(&scene, "cornell", &points(&scene)[3]);
        assert!(
            k.ends_with("|bounce axis inf") && k.contains("voxels"),
            "{k}"
        );
        let quick = args(true).plan().unwrap();
        assert!(!quick.bounce_axis && points(&quick).is_empty());
        assert_eq!(quick.truth_bounces(quick.axis_frame()), Bounces::ONE);
    }
}
