//! Method `multires-gather` (docs/algorithm.md sections 3 and 4): every patch
//! of the multiresolution buffer gathers the N regular VPLs (one level of the
//! RSM quadtree), with the stencil rejecting non-patches before the shader.
//! Its light-space source is the regular VPLs' list (`RegularVpls::list`,
//! pass `vpl-list`), which the framework's list gather loops over; the other
//! passes are those of [`MultiresMethod`].

use super::{Descriptor, IndirectMethod};
use crate::frame::Setup;
use crate::gpu_types::LightPatch;
use crate::multires::MultiresMethod;
use crate::regular_vpls::RegularVpls;
use crate::settings::{Method, RenderSettings};
use anyhow::Result;

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
        let list = RegularVpls::of(setup.settings).list(setup)?;
        Ok(Box::new(MultiresMethod::gathering(setup, Box::new(list))?))
    }
}
