//! Method `multires-gather` (docs/algorithm.md sections 3 and 4): every patch
//! of the multiresolution buffer gathers the N regular VPLs (one level of the
//! RSM quadtree), with the stencil rejecting non-patches before the shader.
//! Pass `vpl-list` (`shaders/regular_vpls/list.comp`) writes the N VPLs into one
//! buffer once per frame, which the gather then loops over as Basic ISR's
//! list; the other passes are those of [`MultiresMethod`].

use super::gather::{GatherPass, LightPatches};
use super::multires_method::{MultiresMethod, PatchList, PatchListPass};
use super::vpls::RegularVpls;
use super::{Descriptor, IndirectMethod};
use crate::frame::Setup;
use crate::gpu_types::LightPatch;
use crate::settings::{Method, RenderSettings};
use anyhow::{anyhow, Result};
use ash::vk;

pub const KEY: Method = Method::new("multires-gather");

pub struct MultiresGatherMethod;

impl Descriptor for MultiresGatherMethod {
    fn key(&self) -> Method {
        KEY
    }
    fn color(&self) -> [u8; 3] {
        [31, 119, 180]
    }
    fn help(&self) -> &'static str {
        "Stenciled gathering from N regular VPLs into the multiresolution buffer."
    }
    fn uses_multires(&self) -> bool {
        true
    }
    fn reads_regular_vpls(&self) -> bool {
        true
    }
    fn reads_visibility(&self) -> bool {
        true
    }
    /// The VPL list.
    fn memory(&self, s: &RenderSettings) -> u64 {
        RegularVpls::of(s).count as u64 * std::mem::size_of::<LightPatch>() as u64
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        let v = RegularVpls::of(setup.settings);
        let list = PatchListPass::new(
            setup,
            PatchList::RegularVpls,
            ("vpl-list", "regular_vpls/list.comp", "VplList"),
            v.count as u64,
            vk::Extent2D {
                width: v.side,
                height: v.side,
            },
        )?;
        let method = MultiresMethod::new(setup, Some(Box::new(list)), |setup, m, list| {
            let list = list.ok_or_else(|| anyhow!("multires-gather gathers from its VPL list"))?;
            Ok(Box::new(GatherPass::new(
                setup,
                m,
                LightPatches::List,
                list,
            )?))
        })?;
        Ok(Box::new(method))
    }
}
