//! Method `multires-gather` (docs/algorithm.md sections 3 and 4): every patch
//! of the multiresolution buffer gathers the N regular VPLs (one level of the
//! RSM quadtree), with the stencil rejecting non-patches before the shader.
//! Pass `vpl-list` (`shaders/vpl_list.comp`) writes the N VPLs into one
//! buffer once per frame, which the gather then loops over as Basic ISR's
//! list; the other passes are those of [`MultiresMethod`].

use super::gather::{GatherPass, LightPatches, MultiresMethod, PatchList, PatchListPass};
use crate::frame::Setup;
use anyhow::{anyhow, Result};
use ash::vk;

pub fn new(setup: &Setup) -> Result<MultiresMethod> {
    let side = (setup.settings.vpls as f64).sqrt() as u32;
    let list = PatchListPass::new(
        setup,
        PatchList::RegularVpls,
        ("vpl-list", "vpl_list.comp", "VplList"),
        setup.settings.vpls as u64,
        vk::Extent2D {
            width: side,
            height: side,
        },
    )?;
    MultiresMethod::new(setup, Some(Box::new(list)), |setup, m, list| {
        let list = list.ok_or_else(|| anyhow!("multires-gather gathers from its VPL list"))?;
        Ok(Box::new(GatherPass::new(
            setup,
            m,
            LightPatches::List,
            list,
        )?))
    })
}
