//! HISR's light-space source (docs/algorithm.md sections 4.3 and 4.4): pass
//! `light-tree-pack` (`shaders/hisr/tree_pack.comp`) copies the RSM
//! quadtree's nodes down to the max depth into one buffer, root first, each
//! with its squared reach; with tiles (`--hisr-tile-level`), pass `hisr-cut`
//! finds each eye-space tile's shared cut (`cut`); then the gather
//! (`shaders/hisr/gather.frag`) traverses per fragment.

use super::cut::CutPass;
use super::{constants, packed_nodes, MAX_DEPTH, TILE_LEVEL};
use crate::frame::{FrameContext, Setup};
use crate::multires::{LightPatches, LightSource, PatchList};
use crate::vk::pipeline::{Binding, Spec};
use crate::vk::profiler::Profiler;
use anyhow::Result;
use ash::vk;

/// The packing, then (with tiles) the cut.
pub struct HisrSource {
    pack: PatchList,
    cut: Option<CutPass>,
    /// The run's HISR constants (`constants`), for the gather.
    constants: [Spec; 5],
}

impl HisrSource {
    pub fn new(setup: &Setup) -> Result<Self> {
        let constants = constants(setup.settings);
        let nodes = packed_nodes(setup.settings);
        // One invocation per node: 2^max_depth wide, enough rows for every node.
        let width = 1u64 << MAX_DEPTH.get(setup.settings);
        let extent = vk::Extent2D {
            width: width as u32,
            height: nodes.div_ceil(width) as u32,
        };
        let pack = PatchList::new(
            setup,
            ("light-tree-pack", "hisr/tree_pack.comp", &constants),
            false,
            nodes,
            extent,
        )?;
        let cut = match TILE_LEVEL.get(setup.settings) {
            0 => None,
            _ => Some(CutPass::new(setup, pack.buffer(), &constants)?),
        };
        Ok(Self {
            pack,
            cut,
            constants,
        })
    }
}

impl LightSource for HisrSource {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        self.pack.record_list(ctx, profiler);
        if let Some(cut) = &self.cut {
            cut.record(ctx, profiler);
        }
    }

    fn gather_shader(&self) -> &'static str {
        "hisr/gather.frag"
    }

    /// The packed tree and the cuts (the tree's buffer again without tiles:
    /// the shader declares the binding, and reads it only with tiles).
    fn gather_bindings(&self) -> Vec<Binding<'_>> {
        let cuts = self.cut.as_ref().map_or(self.pack.buffer(), |c| c.buffer());
        vec![
            Binding::storage("LightTree", self.pack.buffer()),
            Binding::storage("HisrCut", cuts),
        ]
    }

    /// The run's constants, whether the traversal starts from the tiles'
    /// cuts, and the tiles' shared visibility with its refinement spread.
    fn gather_constants(&self) -> Vec<Spec> {
        let shared = self.cut.as_ref().and_then(|c| c.shared_refine());
        let mut v = self.constants.to_vec();
        v.extend([
            Spec::bool("TILED", self.cut.is_some()),
            Spec::bool("SHARED_VISIBILITY", shared.is_some()),
            Spec::float("REFINE_SPREAD", shared.unwrap_or(1.0)),
        ]);
        v
    }

    fn light_patches(&self) -> LightPatches<'_> {
        self.pack.light_patches()
    }
}
