//! Method `isr` (Basic image-space radiosity, docs/algorithm.md section 4): per
//! frame, the largest valid patches of the RSM quadtree above a dense base
//! level, compacted on the GPU into one list that every eye-space patch
//! gathers from (`methods::gather`).
//!
//! Pass `isr-select`: `shaders/isr_select.comp`, one dispatch over the base
//! level with an atomic append (a [`PatchListPass`]). Reads the RSM quadtree;
//! writes the chosen list.

use super::gather::{GatherPass, LightPatches, MultiresMethod, PatchList, PatchListPass};
use crate::frame::Setup;
use anyhow::{anyhow, Result};

/// Method `isr`: the selection, then every eye-space patch gathers the list.
pub fn new(setup: &Setup) -> Result<MultiresMethod> {
    // The RSM quadtree level to start from (also in the run uniforms); at
    // most one chosen patch per base texel, one invocation each.
    let base_extent = setup
        .targets
        .rsm_position
        .mip_extent(setup.settings.isr_base_mip());
    let base_texels = base_extent.width as u64 * base_extent.height as u64;
    let select = PatchListPass::new(
        setup,
        PatchList::IsrChosen,
        ("isr-select", "isr_select.comp", "ChosenPatches"),
        base_texels,
        base_extent,
    )?;
    MultiresMethod::new(setup, Some(Box::new(select)), |setup, m, chosen| {
        let chosen = chosen.ok_or_else(|| anyhow!("isr gathers from its chosen list"))?;
        Ok(Box::new(GatherPass::new(
            setup,
            m,
            LightPatches::List,
            chosen,
        )?))
    })
}
