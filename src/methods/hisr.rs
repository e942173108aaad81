//! Method `hisr` (Hierarchical image-space radiosity, docs/algorithm.md
//! section 4): every eye-space patch traverses the RSM quadtree itself,
//! subdividing light patches whose contribution could exceed tau. The
//! traversal is in `shaders/multires/gather.frag` (`traverse`, with the derivation of
//! the bound) and reads the quadtree packed into one buffer by the pass
//! below, starting from its eye-space tile's shared cut (`hisr-cut`); this
//! module declares the method and its parameters, and makes its passes.

use super::gather::{GatherPass, LightPatches};
use super::multires_method::{
    written_for_gather, LightSpacePass, MultiresMethod, PatchList, PatchListPass,
};
use super::{Descriptor, IndirectMethod};
use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{
    HisrCutHeader, LightPatch, RunUniforms, HISR_CUT_LEVELS, HISR_TAU_ABSOLUTE, HISR_TAU_RELATIVE,
};
use crate::multires;
use crate::passes::{rsm_tree, ComputePass, INDIRECT_COMPUTE};
use crate::settings::params::{AnyParam, Choices, DefaultValue, Param, Range};
use crate::settings::{Method, Params, RenderSettings};
use crate::vk::barrier;
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::{anyhow, bail, Result};

mod cut_layout;
use ash::vk;
pub use cut_layout::{cut_bytes, cut_layout};
use gpu_allocator::MemoryLocation;

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
    default: DefaultValue::Fixed(0.2),
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
pub fn unused_sharing_warning(s: &RenderSettings) -> Option<String> {
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

/// T at the finest level for `tau` given as a fraction of the light's peak
/// intensity I: T = 2 (I - tau I) / (3 tau I R^2) = 2 (1 - tau) / (3 tau R^2)
/// (`shaders/multires/gather.frag` derives the test; this is the one place T is
/// computed, for the run uniforms).
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
    fn write_uniforms(&self, s: &RenderSettings, u: &mut RunUniforms) {
        u.hisr_threshold = subdivision_threshold(TAU.get(s), s.rsm_resolution);
        u.hisr_tau = TAU.get(s);
        u.hisr_tau_mode = match TAU_MODE.get(s) {
            TauMode::Relative => HISR_TAU_RELATIVE,
            TauMode::Absolute => HISR_TAU_ABSOLUTE,
        };
        u.hisr_start_depth = START_LEVEL.get(s) as i32;
        u.hisr_max_depth = MAX_DEPTH.get(s) as i32;
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
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        Ok(Box::new(make(setup)?))
    }
}

/// HISR's points in the bench (docs/algorithm.md section 6.5), for the
/// relative tau (the default mode): tau from its cheap end to its accurate
/// one, shallower trees at the cheap end, two eye-space refinement
/// thresholds, and the accurate end at the default depth.
fn sweep(rsm: u32, quick: bool) -> Vec<Params> {
    let tau = |t: f32| Params::new().with(&TAU, t);
    if quick {
        // 0.2, the default.
        return vec![tau(0.2), tau(0.05)];
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
    // against the dense gather (docs/algorithm.md 4.3). 0.2 is the default.
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

/// Method `hisr`: pass `light-tree-pack` (`shaders/hisr/tree_pack.comp`)
/// copies the RSM quadtree's nodes down to the max depth into one buffer, root
/// first; with tiles (`--hisr-tile-level`), pass `hisr-cut` finds each
/// eye-space tile's shared cut; then the gather traverses per fragment.
fn make(setup: &Setup) -> Result<MultiresMethod> {
    let nodes = packed_nodes(setup.settings);
    // One invocation per node: 2^max_depth wide, enough rows for every node.
    let width = 1u64 << MAX_DEPTH.get(setup.settings);
    let extent = vk::Extent2D {
        width: width as u32,
        height: nodes.div_ceil(width) as u32,
    };
    let pack = PatchListPass::new(
        setup,
        PatchList::PackedTree,
        ("light-tree-pack", "hisr/tree_pack.comp", "LightTree"),
        nodes,
        extent,
    )?;
    let cut = match TILE_LEVEL.get(setup.settings) {
        0 => None,
        _ => Some(CutPass::new(setup, pack.patch_buffer())?),
    };
    let source = match cut {
        Some(_) => LightPatches::TiledTraversal,
        None => LightPatches::Traversal,
    };
    let light = HisrLightPass { pack, cut };
    MultiresMethod::new(setup, Some(Box::new(light)), move |setup, m, light| {
        let light = light.ok_or_else(|| anyhow!("hisr gathers from its packed tree"))?;
        Ok(Box::new(GatherPass::new(setup, m, source, light)?))
    })
}

/// Nodes in HISR's packed tree: every depth from the root down to the max
/// depth, `(4^(D+1) - 1) / 3`. Deeper nodes are never read (nodes at the max
/// depth never split), so they are not packed: at RSM 1024 and depth 6 that is
/// 5,461 nodes instead of 1.4 million.
pub fn packed_nodes(s: &RenderSettings) -> u64 {
    let side = 1u64 << MAX_DEPTH.get(s);
    (4 * side * side - 1) / 3
}

/// HISR's light-space passes: the packing, then (with tiles) the cut.
struct HisrLightPass {
    pack: PatchListPass,
    cut: Option<CutPass>,
}

impl LightSpacePass for HisrLightPass {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        self.pack.record(ctx, profiler);
        if let Some(cut) = &self.cut {
            cut.record(ctx, profiler);
        }
    }

    fn patch_buffer(&self) -> &Buffer {
        self.pack.patch_buffer()
    }

    fn packed_tree(&self) -> Option<&Buffer> {
        self.pack.packed_tree()
    }

    fn tile_cuts(&self) -> Option<&Buffer> {
        self.cut.as_ref().map(|c| &c.buffer)
    }

    fn shared_visibility_refine(&self) -> Option<f32> {
        self.cut
            .as_ref()
            .and_then(|c| c.visibility.as_ref().map(|_| c.refine))
    }
}

/// Pass `hisr-cut` (`shaders/hisr/cut.comp`, docs/algorithm.md section 4.4):
/// one dispatch for the finest tiles' boxes of G-buffer positions, then one
/// per chained level, coarsest first, one invocation per eye-space tile.
/// Reads the G-buffer positions, the packed tree, the boxes and the coarser
/// level's cuts; writes the cut buffer (barriers in `record`).
struct CutPass {
    boxes: ComputePass,
    pass: ComputePass,
    /// Pass `hisr-visibility` (`shaders/hisr/visibility.comp`), with shared
    /// visibility.
    visibility: Option<ComputePass>,
    /// `--hisr-shared-refine`, for the gather.
    refine: f32,
    buffer: Buffer,
    header: HisrCutHeader,
}

impl CutPass {
    fn new(setup: &Setup, tree: &Buffer) -> Result<Self> {
        let header = cut_layout(setup.settings);
        let buffer = Buffer::new(
            setup.gpu,
            "hisr-cut",
            cut_bytes(setup.settings),
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        let (t, s) = (setup.targets, setup.samplers);
        let bindings = vec![
            Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
            Binding::storage("LightTree", tree),
            Binding::storage("HisrCut", &buffer),
        ];
        let push_bytes = std::mem::size_of::<HisrCutHeader>() as u32 + 4;
        // Specialisation constant 0 (BOXES): the boxes' dispatch or the cuts'.
        let pass = |boxes: bool| {
            ComputePass::new(
                setup,
                "hisr-cut",
                "hisr/cut.comp",
                std::slice::from_ref(&bindings),
                push_bytes,
                &[crate::vk::pipeline::Spec::bool("BOXES", boxes)],
            )
        };
        let visibility = match shares_visibility(setup.settings) {
            true => Some(ComputePass::new(
                setup,
                "hisr-visibility",
                "hisr/visibility.comp",
                &[vec![
                    Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
                    Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
                    Binding::storage("LightTree", tree),
                    Binding::storage("HisrCut", &buffer),
                ]],
                0,
                // REFINE_SPREAD: which entries get their march bit; the
                // grid's layout and march.
                &[
                    crate::vk::pipeline::Spec::float(
                        "REFINE_SPREAD",
                        SHARED_REFINE.get(setup.settings),
                    ),
                    crate::voxel_grid::specialization(setup.settings),
                ],
            )?),
            false => None,
        };
        Ok(Self {
            boxes: pass(true)?,
            pass: pass(false)?,
            visibility,
            refine: SHARED_REFINE.get(setup.settings),
            buffer,
            header,
        })
    }

    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let readers = vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COPY;
        profiler.pass(gpu, cmd, "hisr-cut", INDIRECT_COMPUTE, || {
            // The packed tree, just written, is read here; the previous
            // gather (of this frame's previous light view or the previous
            // frame) and readback read the cuts before they are overwritten.
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::COMPUTE_SHADER | readers,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
            );
            let push = |c: usize| {
                let mut push = bytemuck::bytes_of(&self.header).to_vec();
                push.extend_from_slice(&(c as i32).to_ne_bytes());
                push
            };
            let [tx, ty, ..] = self.header.tiles[0];
            let finest = vk::Extent2D {
                width: tx,
                height: ty,
            };
            self.boxes.dispatch(ctx, 0, &push(0), finest);
            for c in (0..HISR_CUT_LEVELS).rev() {
                // Level c reads the boxes and level c + 1's cuts.
                barrier::compute_to_compute(gpu, cmd);
                let push = push(c);
                // One invocation per tile.
                let [tx, ty, ..] = self.header.tiles[c];
                let extent = vk::Extent2D {
                    width: tx,
                    height: ty,
                };
                self.pass.dispatch(ctx, 0, &push, extent);
            }
            written_for_gather(ctx);
        });
        if let Some(visibility) = &self.visibility {
            profiler.pass(gpu, cmd, "hisr-visibility", INDIRECT_COMPUTE, || {
                // The cuts just written are read here (and the previous
                // gather's reads of the visibilities were ordered before
                // hisr-cut's first dispatch).
                barrier::compute_to_compute(gpu, cmd);
                // One workgroup of 8x8 per finest tile (frame::check
                // holds the tiles a side within the device's workgroups).
                let [tx, ty, ..] = self.header.tiles[0];
                let extent = vk::Extent2D {
                    width: 8 * tx,
                    height: 8 * ty,
                };
                visibility.dispatch(ctx, 0, &[], extent);
                written_for_gather(ctx);
            });
        }
    }
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
