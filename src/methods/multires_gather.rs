//! Method `multires-gather` (docs/algorithm.md sections 3 and 4): every patch
//! of the multiresolution buffer gathers the N regular VPLs (one level of the
//! RSM quadtree), with the stencil rejecting non-patches before the shader.
//! The passes are those of [`MultiresMethod`] with the gather reading
//! [`LightPatches::Regular`].

use super::gather::{GatherPass, LightPatches, MultiresMethod};
use crate::frame::Setup;
use anyhow::Result;

pub fn new(setup: &Setup) -> Result<MultiresMethod> {
    MultiresMethod::new(setup, None, |setup, m, _| {
        Ok(Box::new(GatherPass::new(
            setup,
            m,
            LightPatches::Regular,
            None,
        )?))
    })
}
