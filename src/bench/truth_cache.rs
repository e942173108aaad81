//! The path-traced truth and the exact-visibility floor of each bench frame
//! (docs/algorithm.md section 6.6), cached in the run's folder
//! (`truth/SCENE/frame-K.exr`, `frame-K-bounces-N.exr` for a truth of N
//! bounces, and `exact-K.exr`, each with a JSON note) so that a run that
//! stops resumes without tracing them again.

use super::files::exr_layer;
use super::truth::{self, trace, truth_mask, ShadowMaps, Truth};
use super::{frame_time, Plan, SceneSpec};
use crate::bounces::Bounces;
use crate::readback::Readback;
use crate::renderer::Renderer;
use crate::scene::Scene;
use anyhow::{Context as _, Result};
use std::path::Path;

/// The dense reference's indirect image of frame `k` of `spec` with exact
/// visibility (`visibility::with_exact_visibility`; `out` is the frame `r`
/// rendered), cached beside the truth (`truth/SCENE/exact-K.exr`) as it
/// takes minutes on a CPU.
pub(super) fn model_floor(
    plan: &Plan,
    spec: &SceneSpec,
    k: u32,
    posed: &Scene,
    r: &mut Renderer,
    out: &Readback,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<[f32; 4]>> {
    let path = super::files::truth_dir(&plan.out_dir, &spec.name).join(format!("exact-{k}.exr"));
    let time = frame_time(spec, k);
    if let Some(cached) = cached_exact(&path, out, time, plan.base.rsm_resolution) {
        return Ok(cached);
    }
    let message = |done: usize, rows: usize| {
        bar.set_message(format!(
            "{}: the reference with exact visibility, frame {}: row {done}/{rows}",
            spec.name,
            k + 1
        ))
    };
    let exact =
        crate::exact_visibility::with_exact_visibility(r, posed, out.clone(), 1.0, message)?;
    write_exact(&path, &exact, time, plan.base.rsm_resolution)?;
    if bar.is_hidden() {
        eprintln!(
            "{}: the reference with exact visibility at frame {}",
            spec.name,
            k + 1
        );
    }
    Ok(exact.indirect)
}

/// The path-traced truth of frame `k` of `spec` at the run's noise target
/// and bounces (`--bounces`; every bounce at the bounces axis's frame,
/// whose layers hold the truth of one: `Plan::truth_bounces`), cached in the run's folder
/// (`truth/SCENE/frame-K.exr`, with a note of its bounces, samples and
/// noise), compared on the pixels of `g` (the reference's G-buffer, whose
/// RSMs `r` holds) away from edges.
pub(super) fn frame_truth(
    plan: &Plan,
    spec: &SceneSpec,
    k: u32,
    posed: &Scene,
    r: &Renderer,
    g: &Readback,
    bar: &indicatif::ProgressBar,
) -> Result<truth::Truth> {
    let key = FrameKey {
        time: frame_time(spec, k),
        target: plan.truth_noise.unwrap_or(truth::NOISE_TARGET),
        seed: k as u64 + 1,
        bounces: plan.truth_bounces(k),
    };
    let path = super::files::truth_dir(&plan.out_dir, &spec.name)
        .join(super::bounces::truth_file(k, key.bounces));
    let what = super::bounces::truth_words(key.bounces);
    let shadows = truth::ShadowMaps::new(
        r.light_views(),
        r.render_origin(),
        plan.base.shadow_size(),
        plan.base.pcf_radius,
    );
    let message = |spp: u32, noise: f64| {
        bar.set_message(format!(
            "{}: {what}, frame {}/{}: {spp} spp, noise {:.1}%",
            spec.name,
            k + 1,
            plan.frames,
            100.0 * noise
        ))
    };
    message(0, f64::NAN);
    let t = traced_or_cached(&path, posed, g, &shadows, key, message)
        .with_context(|| format!("the path-traced truth of {} frame {k}", spec.name))?;
    if bar.is_hidden() {
        // No terminal (a log, CI): a line per frame, as per row.
        eprintln!(
            "{}: {what} of frame {}/{}: {} spp, noise {:.4}, {:.1}% of pixels left out",
            spec.name,
            k + 1,
            plan.frames,
            t.spp,
            t.noise,
            100.0 * t.mask.left_out()
        );
    }
    Ok(t)
}

/// What a cached truth records beside its image (`FILE.json`).
#[derive(serde::Serialize, serde::Deserialize)]
struct CacheNote {
    width: u32,
    height: u32,
    time: f32,
    /// Its bounces as `--bounces` writes them; a note written before the
    /// bounces were noted is of one bounce, all the path tracer traced then.
    #[serde(default = "one_bounce")]
    bounces: String,
    target: f64,
    spp: u32,
    noise: f64,
    /// The noise of the sum of its first n layers by bounce (n from 1),
    /// where noted (`Truth::noises`); else its one `noise`.
    #[serde(default)]
    noises: Vec<f64>,
}

fn one_bounce() -> String {
    use crate::settings::ParamType as _;
    Bounces::ONE.text()
}

/// A truth traced before for this frame (`path` and its note), if its size,
/// time and bounces match and it was traced for this noise target or
/// measured under it; anything else is traced again. The bounces must
/// match exactly: a truth of other bounces is another image, and its noise
/// was measured on that image.
fn cached(path: &Path, g: &Readback, key: &FrameKey) -> Option<(Readback, u32, f64, Vec<f64>)> {
    use crate::settings::ParamType as _;
    let note: CacheNote =
        serde_json::from_slice(&std::fs::read(path.with_extension("json")).ok()?).ok()?;
    let target = key.target;
    // A truth traced for a tighter target serves a looser one as it is.
    if (note.width, note.height) != (g.width, g.height)
        || note.time != key.time
        || note.bounces != key.bounces.text()
        || !(note.target == target || note.noise <= target)
    {
        return None;
    }
    let image = exr::prelude::read_all_flat_layers_from_file(path).ok()?;
    let n = (g.width * g.height) as usize;
    let mut r = g.clone();
    r.direct = exr_layer(&image, "direct", n)?;
    r.indirect = exr_layer(&image, "indirect", n)?;
    r.final_radiance = exr_layer(&image, "final", n)?;
    let by_bounce: Option<Vec<_>> = crate::bounces::LAYERS[..key.bounces.layers()]
        .iter()
        .map(|name| exr_layer(&image, name, n))
        .collect();
    r.bounces = match by_bounce {
        Some(layers) => layers,
        // Cached before the light was kept by bounce: of one bounce, so
        // `indirect` is its first bounce.
        None if key.bounces == Bounces::ONE => vec![r.indirect.clone()],
        None => return None,
    };
    let noises = match note.noises.len() == r.bounces.len() {
        true => note.noises,
        false => vec![note.noise; r.bounces.len()],
    };
    Some((r, note.spp, note.noise, noises))
}

/// Which truth of a scene a bench frame needs: its animation time, the
/// noise target, the seed of its first samples and its bounces.
#[derive(Clone, Copy, Debug)]
pub struct FrameKey {
    pub time: f32,
    pub target: f64,
    pub seed: u64,
    pub bounces: Bounces,
}

/// The truth of one bench frame: read from `path` when traced before for
/// the same size, time and bounces, to this noise target or under it, else
/// traced (see [`trace`]) and written there (an EXR of the path tracer's
/// layers and a JSON note), so that a run that stops resumes without
/// tracing it again.
fn traced_or_cached(
    path: &Path,
    posed: &crate::scene::Scene,
    g: &Readback,
    shadows: &ShadowMaps,
    key: FrameKey,
    progress: impl Fn(u32, f64),
) -> anyhow::Result<Truth> {
    if let Some((image, spp, noise, noises)) = cached(path, g, &key) {
        let mask = truth_mask(g, &image.direct, shadows);
        return Ok(Truth {
            image,
            bounces: key.bounces,
            mask,
            spp,
            noise,
            noises,
        });
    }
    let FrameKey {
        time,
        target,
        seed,
        bounces,
    } = key;
    let truth = trace(posed, g, shadows, target, seed, bounces, progress);
    crate::output::write_exr(path, &truth.image)?;
    let note = CacheNote {
        width: g.width,
        height: g.height,
        time,
        bounces: crate::settings::ParamType::text(bounces),
        target,
        spp: truth.spp,
        noise: truth.noise,
        noises: truth.noises.clone(),
    };
    crate::output::write_text(
        &path.with_extension("json"),
        &serde_json::to_string_pretty(&note)?,
    )?;
    Ok(truth)
}

/// What a cached exact-visibility reference records beside its image.
#[derive(serde::Serialize, serde::Deserialize)]
struct ExactNote {
    width: u32,
    height: u32,
    time: f32,
    rsm: u32,
}

/// The indirect image of an exact-visibility reference written before for
/// this frame (`path` and its note), if its size, time and RSM match.
fn cached_exact(path: &Path, g: &Readback, time: f32, rsm: u32) -> Option<Vec<[f32; 4]>> {
    let note: ExactNote =
        serde_json::from_slice(&std::fs::read(path.with_extension("json")).ok()?).ok()?;
    if (note.width, note.height, note.rsm) != (g.width, g.height, rsm) || note.time != time {
        return None;
    }
    let image = exr::prelude::read_all_flat_layers_from_file(path).ok()?;
    exr_layer(&image, "indirect", (g.width * g.height) as usize)
}

/// Writes an exact-visibility reference frame for [`cached_exact`].
fn write_exact(path: &Path, r: &Readback, time: f32, rsm: u32) -> anyhow::Result<()> {
    crate::output::write_exr(path, r)?;
    let note = ExactNote {
        width: r.width,
        height: r.height,
        time,
        rsm,
    };
    crate::output::write_text(
        &path.with_extension("json"),
        &serde_json::to_string_pretty(&note)?,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::readback::RsmReadback;

    /// A 4x4 image whose every layer holds `v`, without layers by bounce
    /// (as truths were cached before there were bounces).
    fn image(v: f32) -> Readback {
        let n = 16;
        Readback {
            width: 4,
            height: 4,
            final_radiance: vec![[v; 4]; n],
            direct: vec![[v; 4]; n],
            indirect: vec![[v; 4]; n],
            bounces: vec![],
            albedo: vec![[v; 4]; n],
            normal: vec![[0.0, 1.0, 0.0, 0.0]; n],
            position: vec![[0.0, 0.0, 0.0, 1.0]; n],
            display: vec![],
            rsm: RsmReadback {
                resolution: 0,
                position: vec![],
                normal: vec![],
                flux: vec![],
            },
        }
    }

    #[test]
    fn a_truth_serves_its_own_bounces_only_and_old_notes_are_of_one_bounce() {
        let dir = std::env::temp_dir().join(format!("isr-truth-cache-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("frame-0.exr");
        crate::output::write_exr(&path, &image(0.5)).unwrap();
        // A note as written before the bounces were noted.
        let old =
            r#"{"width": 4, "height": 4, "time": 0.0, "target": 0.1, "spp": 64, "noise": 0.05}"#;
        std::fs::write(path.with_extension("json"), old).unwrap();
        let key = |bounces| FrameKey {
            time: 0.0,
            target: 0.1,
            seed: 1,
            bounces,
        };
        let g = image(0.0);
        let (r, spp, _, _) = cached(&path, &g, &key(Bounces::ONE)).expect("served as one bounce");
        assert_eq!(spp, 64);
        assert_eq!(r.bounces, vec![r.indirect.clone()]);
        assert!(cached(&path, &g, &key(Bounces::Count(2))).is_none());
        assert!(cached(&path, &g, &key(Bounces::Infinite)).is_none());
        // A truth of every bounce, with its layers, serves every bounce
        // alone, and not one.
        let mut every = image(0.5);
        every.bounces = vec![vec![[0.125; 4]; 16]; 4];
        crate::output::write_exr(&path, &every).unwrap();
        let note = CacheNote {
            width: 4,
            height: 4,
            time: 0.0,
            bounces: "inf".into(),
            target: 0.1,
            spp: 64,
            noise: 0.05,
            noises: vec![],
        };
        let json = serde_json::to_string(&note).unwrap();
        std::fs::write(path.with_extension("json"), json).unwrap();
        let (r, _, _, _) = cached(&path, &g, &key(Bounces::Infinite)).expect("served");
        assert_eq!(r.bounces.len(), 4);
        assert_eq!(r.bounces[3][0][0], 0.125);
        assert!(cached(&path, &g, &key(Bounces::ONE)).is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
