//! Method `hisr` (Hierarchical image-space radiosity, docs/algorithm.md
//! section 4): every eye-space patch traverses the RSM quadtree itself,
//! subdividing light patches whose contribution could exceed tau. The
//! traversal is in `shaders/hisr/gather.frag` (`traverse`, with the
//! derivation of the bound) and reads the quadtree packed into one buffer
//! by the light-space source (`source`: pass `light-tree-pack`), starting
//! from its eye-space tile's shared cut (`cut`: pass `hisr-cut`); this
//! module declares the method, its parameters and the specialization
//! constants that carry them to `shaders/hisr/`.

use super::{Descriptor, IndirectMethod};
use crate::frame::Setup;
use crate::gpu_types::LightPatch;
use crate::multires::{self, MultiresMethod};
use crate::passes::rsm_tree;
use crate::settings::params::{AnyParam, Choices, DefaultValue, Param, Range};
use crate::settings::{Method, Params, RenderSettings};
use crate::vk::pipeline::Spec;
use anyhow::{bail, Result};

mod cut;
mod cut_layout;
pub mod gpu;
mod source;
pub use cut_layout::{cut_bytes, cut_layout};

pub const KEY: Method = Method::new("hisr");

/// The deepest tree the packing addresses (`cut_entry` in `shaders/hisr/hisr.glsl`
/// keeps 12 bits per coordinate): an RSM of 4096.
const MAX_TREE_DEPTH: f64 = 12.0;

/// The largest `--hisr-tile-level` (tiles of 256 x 256 pixels).
pub const MAX_TILE_LEVEL: u32 = 8;

pub const START_LEVEL: Param<u32> = Param {
    name: "start-level",
    help: "HISR starts its traversal from 2^s x 2^s light patches",
    default: DefaultValue::Fixed(2),
    range: Range::closed(0.0, MAX_TREE_DEPTH),
};

pub const MAX_DEPTH: Param<u32> = Param {
    name: "max-depth",
    help: "HISR subdivides at most down to 2^d x 2^d light patches (at most log2 of --rsm); \
           patches spanning a discontinuity are held to 1/100 of tau",
    // Single RSM texels up to RSM 256, so that tau sets the error
    // (docs/algorithm.md 4.3); beyond, depth 8 bounds the packed tree
    // (87,381 nodes, 4 MiB) and the traversal whatever the RSM.
    default: DefaultValue::Derived(
        |s| 8.min(s.rsm_top_level()),
        "8, or log2 of --rsm if smaller",
    ),
    range: Range::closed(0.0, MAX_TREE_DEPTH),
};

pub const TAU: Param<f32> = Param {
    name: "tau",
    help: "HISR's error threshold: a light patch is subdivided while its solid angle seen \
           from the receiver exceeds tau (--hisr-tau-mode relative), or while its contribution \
           could exceed tau * I (absolute)",
    // The best balance (docs/results.md, "Best balance"): with the grid, the
    // cheapest tau within 1.25x of the lowest error against the truth.
    default: DefaultValue::Fixed(0.05),
    range: Range::open(0.0, 1.0),
};

/// What `--tau` bounds (docs/algorithm.md section 4.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TauMode {
    /// A light patch splits while its solid angle seen from the receiver,
    /// `A_j / (pi |V_ij|^2 + A_j)`, exceeds tau: each evaluated patch then
    /// errs by a small fraction of its own contribution, so a receiver errs
    /// by about that fraction of its total indirect irradiance.
    Relative,
    /// The talk's test: while its bound exceeds tau times the light's peak
    /// intensity over the squared distance to the patch.
    Absolute,
}

impl Choices for TauMode {
    const NAMES: &'static [(&'static str, &'static str)] = &[
        (
            "relative",
            "split while a light patch's solid angle seen from the receiver exceeds tau \
             (the error is a like fraction of the indirect light on any scene)",
        ),
        (
            "absolute",
            "the talk's test: split while a light patch's bound exceeds tau times the light's \
             peak intensity over the squared distance to the patch",
        ),
    ];
    fn index(self) -> usize {
        self as usize
    }
    fn from_index(i: usize) -> Self {
        [TauMode::Relative, TauMode::Absolute][i]
    }
}

pub const TAU_MODE: Param<TauMode> = Param {
    name: "hisr-tau-mode",
    help: "What HISR's --tau bounds: each evaluated light patch's solid angle seen from the \
           receiver (relative), or its contribution as a fraction of the light's peak \
           intensity (absolute, the talk's form)",
    default: DefaultValue::Fixed(TauMode::Relative),
    range: Range::ANY,
};

pub const TILE_LEVEL: Param<u32> = Param {
    name: "hisr-tile-level",
    help: "HISR finds the traversal shared by each tile of 2^K, 2^(K+1) and 2^(K+2) pixels \
           a side once per tile (pass hisr-cut); 0 traverses from the roots in every \
           fragment. Same image either way (up to float rounding)",
    default: DefaultValue::Fixed(4),
    range: Range::closed(0.0, MAX_TILE_LEVEL as f64),
};

pub const SHARED_VISIBILITY: Param<bool> = Param {
    name: "hisr-shared-visibility",
    help: "--visibility voxels: the visibility of each tile's shared light patches is marched \
           from the tile's four corners and interpolated at the receivers (pass \
           hisr-visibility), each receiver marching itself where the corners disagree \
           (--hisr-shared-refine): 0.7-1x the per-receiver march's indirect time, as near \
           the path-traced truth, 1.1x its flicker (docs/algorithm.md section 5); off marches \
           from every receiver",
    // On: as accurate against the truth as the per-receiver march, in less
    // time (docs/algorithm.md section 5, "Tile-shared visibility").
    default: DefaultValue::Fixed(true),
    range: Range::ANY,
};

pub const SHARED_REFINE: Param<f32> = Param {
    name: "hisr-shared-refine",
    help: "--hisr-shared-visibility on: a receiver marches a light patch itself where the \
           tile's corners' visibilities of it differ by more than this, or none has geometry; \
           one on none of the corners' surfaces takes up to 4 further points of the tile on \
           its own (marching where they and the corners differ by more than this), and \
           marches every patch where none is; 0 wherever they differ at all, 1 never marches \
           (the corners alone)",
    // 0: any difference. 0.25 cost the same and let a thin wall leak 7%
    // of the light behind it where the corners read 0 and 0.2 (the grid's
    // chords), docs/algorithm.md section 5.
    default: DefaultValue::Fixed(0.0),
    range: Range::closed(0.0, 1.0),
};

pub const PARAMS: &[&dyn AnyParam] = &[
    &TAU,
    &TAU_MODE,
    &START_LEVEL,
    &MAX_DEPTH,
    &TILE_LEVEL,
    &SHARED_VISIBILITY,
    &SHARED_REFINE,
];

/// The warning for `--hisr-shared-visibility on` or `--hisr-shared-refine`
/// given where they cannot act: without the grid or without tiles (most
/// likely a forgotten `--visibility voxels`).
fn unused_sharing_warning(s: &RenderSettings) -> Option<String> {
    let given =
        (SHARED_VISIBILITY.is_set_in(s) && SHARED_VISIBILITY.get(s)) || SHARED_REFINE.is_set_in(s);
    (given && !shares_visibility(s)).then(|| {
        "warning: the tiles' shared visibility (--hisr-shared-visibility, --hisr-shared-refine) \
         has no effect without --visibility voxels, --hisr-shared-visibility on and \
         --hisr-tile-level above 0"
            .to_string()
    })
}

/// Whether `hisr-visibility` runs: with the grid, tiles, and sharing on.
pub fn shares_visibility(s: &RenderSettings) -> bool {
    crate::visibility::uses_voxels(s) && TILE_LEVEL.get(s) > 0 && SHARED_VISIBILITY.get(s)
}

/// The specialization constants of every shader that includes
/// `shaders/hisr/hisr.glsl`: the run's tau, what it bounds, T (for the
/// absolute tau) and the traversal's start and max depths.
pub fn constants(s: &RenderSettings) -> [Spec; 5] {
    [
        Spec::float("HISR_TAU", TAU.get(s)),
        Spec::bool("HISR_TAU_ABSOLUTE", TAU_MODE.get(s) == TauMode::Absolute),
        Spec::float(
            "HISR_THRESHOLD",
            subdivision_threshold(TAU.get(s), s.rsm_resolution),
        ),
        Spec::int("HISR_START_DEPTH", START_LEVEL.get(s) as i32),
        Spec::int("HISR_MAX_DEPTH", MAX_DEPTH.get(s) as i32),
    ]
}

/// T at the finest level for `tau` given as a fraction of the light's peak
/// intensity I: T = 2 (I - tau I) / (3 tau I R^2) = 2 (1 - tau) / (3 tau R^2)
/// (`shaders/hisr/gather.frag` derives the test; this is the one place T is
/// computed, for `HISR_THRESHOLD`).
pub fn subdivision_threshold(tau: f32, rsm_resolution: u32) -> f32 {
    let r2 = rsm_resolution as f64 * rsm_resolution as f64;
    (2.0 * (1.0 - tau as f64) / (3.0 * tau as f64 * r2)) as f32
}

pub struct HisrMethod;

impl Descriptor for HisrMethod {
    fn key(&self) -> Method {
        KEY
    }
    fn color(&self) -> [u8; 3] {
        [214, 39, 40]
    }
    fn help(&self) -> &'static str {
        "Hierarchical ISR: a per-fragment traversal of the RSM quadtree."
    }
    fn params(&self) -> &'static [&'static [&'static dyn AnyParam]] {
        &[rsm_tree::PARAMS, PARAMS]
    }
    fn uses_multires(&self) -> bool {
        true
    }
    fn reads_visibility(&self) -> bool {
        true
    }
    fn check(&self, s: &RenderSettings) -> Result<()> {
        let top = s.rsm_top_level();
        let (start, max) = (START_LEVEL.get(s), MAX_DEPTH.get(s));
        if max > top || start > max {
            bail!(
                "--start-level {start} and --max-depth {max} must satisfy start <= max <= log2(--rsm) = {top}"
            );
        }
        Ok(())
    }
    /// The packed tree and the tile cuts.
    fn memory(&self, s: &RenderSettings) -> u64 {
        let node = std::mem::size_of::<LightPatch>() as u64;
        packed_nodes(s) * node + cut_bytes(s)
    }
    fn sweep(&self, rsm: u32, quick: bool) -> Vec<Params> {
        sweep(rsm, quick)
    }
    fn label(&self, s: &RenderSettings) -> String {
        let mut l = format!("tau {}, depth {}", TAU.get(s), MAX_DEPTH.get(s));
        if TAU_MODE.get(s) == TauMode::Absolute {
            l += ", absolute";
        }
        let eye = multires::DEPTH_THRESHOLD.get(s);
        if eye != multires::DEPTH_THRESHOLD.default_in(s) {
            l += &format!(", eye depth {eye}");
        }
        l
    }
    fn warnings(&self, s: &RenderSettings) -> Vec<String> {
        unused_sharing_warning(s).into_iter().collect()
    }
    fn main_param(&self) -> Option<&'static dyn AnyParam> {
        Some(&TAU)
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        let source = source::HisrSource::new(setup)?;
        Ok(Box::new(MultiresMethod::gathering(
            setup,
            Box::new(source),
        )?))
    }
}

/// HISR's points in the bench (docs/algorithm.md section 6.5), for the
/// relative tau (the default mode): tau from its cheap end to its accurate
/// one, shallower trees at the cheap end, two eye-space refinement
/// thresholds, and the accurate end at the default depth.
fn sweep(rsm: u32, quick: bool) -> Vec<Params> {
    let tau = |t: f32| Params::new().with(&TAU, t);
    if quick {
        // A cheap point and the default.
        return vec![tau(0.2), tau(TAU.default_in(&RenderSettings::DEFAULT))];
    }
    let at_rsm = RenderSettings {
        rsm_resolution: rsm,
        ..Default::default()
    };
    let deepest = MAX_DEPTH.default_in(&at_rsm);
    let start = START_LEVEL.default_in(&at_rsm);
    let mut v: Vec<Params> = vec![];
    let mut add = |p: Params| {
        if !v.contains(&p) {
            v.push(p);
        }
    };
    // The accurate end, at the default depth (single RSM texels up to RSM
    // 256), where tau alone sets the error: about tau / 4 to tau / 1.6
    // against the dense gather (docs/algorithm.md 4.3). 0.05 is the default.
    for t in [0.5, 0.2, 0.1, 0.05, 0.02, 0.005] {
        add(tau(t));
    }
    // Large taus trace the cheap end of HISR's front: at tau 0.9 a valid
    // patch splits only for receivers it nearly surrounds, an invalid one
    // within 10x that distance. Depth 6 stops at the light patches of 4096
    // regular VPLs, and depths 3 and 4 at the two largest taus go cheaper
    // still.
    let floor = 6.min(deepest);
    for t in [0.97, 0.9, 0.75, 0.5, 0.2] {
        add(if floor == deepest {
            tau(t)
        } else {
            tau(t).with(&MAX_DEPTH, floor)
        });
    }
    for t in [0.97, 0.9] {
        for d in [3, 4] {
            if d >= start && d < deepest {
                add(tau(t).with(&MAX_DEPTH, d));
            }
        }
    }
    for t in [0.05, 0.3] {
        add(Params::new().with(&multires::DEPTH_THRESHOLD, t));
    }
    v
}

/// Nodes in HISR's packed tree: every depth from the root down to the max
/// depth, `(4^(D+1) - 1) / 3`. Deeper nodes are never read (nodes at the max
/// depth never split), so they are not packed: at RSM 1024 and depth 6 that is
/// 5,461 nodes instead of 1.4 million.
pub fn packed_nodes(s: &RenderSettings) -> u64 {
    let side = 1u64 << MAX_DEPTH.get(s);
    (4 * side * side - 1) / 3
}

#[cfg(test)]
mod tests {
    use super::subdivision_threshold;

    #[test]
    fn threshold_falls_as_tau_grows_and_vanishes_at_one() {
        let t = |tau| subdivision_threshold(tau, 256);
        assert!(t(0.001) > t(0.01) && t(0.01) > t(0.1));
        assert_eq!(t(1.0), 0.0);
        // tau = 1/3 at R = 1: T = 2 (2/3) / 1 = 4/3.
        assert!((subdivision_threshold(1.0 / 3.0, 1) - 4.0 / 3.0).abs() < 1e-6);
    }
}
