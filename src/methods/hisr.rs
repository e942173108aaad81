//! Method `hisr` (Hierarchical image-space radiosity, docs/algorithm.md
//! section 4): every eye-space patch traverses the RSM quadtree itself,
//! subdividing light patches whose contribution could exceed tau. The
//! traversal is in `shaders/gather.frag` (`traverse`, with the derivation of
//! the bound) and reads the quadtree packed into one buffer by the pass
//! below; this module makes the method and holds its constants.

use super::gather::{GatherPass, LightPatches, MultiresMethod, PatchList, PatchListPass};
use crate::frame::Setup;
use anyhow::{anyhow, Result};
use ash::vk;

/// Method `hisr`: pass `light-tree-pack` (`shaders/light_tree_pack.comp`)
/// copies every node of the RSM quadtree into one buffer, root first, then
/// the gather traverses it per fragment.
pub fn new(setup: &Setup) -> Result<MultiresMethod> {
    let r = setup.settings.rsm_resolution as u64;
    let nodes = (4 * r * r - 1) / 3;
    // One invocation per node: R wide, enough rows for every node.
    let extent = vk::Extent2D {
        width: r as u32,
        height: nodes.div_ceil(r) as u32,
    };
    let pack = PatchListPass::new(
        setup,
        PatchList::PackedTree,
        ("light-tree-pack", "light_tree_pack.comp", "LightTree"),
        nodes,
        extent,
    )?;
    MultiresMethod::new(setup, Some(Box::new(pack)), |setup, m, tree| {
        let tree = tree.ok_or_else(|| anyhow!("hisr gathers from its packed tree"))?;
        Ok(Box::new(GatherPass::new(
            setup,
            m,
            LightPatches::Traversal,
            tree,
        )?))
    })
}

/// T at the finest level for `tau` given as a fraction of the light's peak
/// intensity I: T = 2 (I - tau I) / (3 tau I R^2) = 2 (1 - tau) / (3 tau R^2).
pub fn subdivision_threshold(tau: f32, rsm_resolution: u32) -> f32 {
    let r2 = rsm_resolution as f64 * rsm_resolution as f64;
    (2.0 * (1.0 - tau as f64) / (3.0 * tau as f64 * r2)) as f32
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
