//! Method `isr` (Basic image-space radiosity, docs/algorithm.md section 4): per
//! frame, the largest valid patches of the RSM quadtree above a dense base
//! level, compacted on the GPU into one list that every eye-space patch
//! gathers from (the multiresolution framework's list gather).
//!
//! Its light-space source, pass `isr-select`: `shaders/isr/select.comp`, one
//! dispatch over the base level with an atomic append (a [`PatchList`]).
//! Reads the RSM quadtree; writes the chosen list.

use super::{Descriptor, IndirectMethod};
use crate::frame::Setup;
use crate::gpu_types::LightPatch;
use crate::multires::{MultiresMethod, PatchList};
use crate::passes::rsm_tree;
use crate::settings::params::{AnyParam, DefaultValue, Param, Range};
use crate::settings::{Method, Params, RenderSettings};
use crate::vk::pipeline::Spec;
use anyhow::{bail, Result};

pub const KEY: Method = Method::new("isr");

pub const BASE: Param<u32> = Param {
    name: "isr-base",
    help: "Basic ISR's dense starting level, in patches per side (a power of 2, at most --rsm)",
    default: DefaultValue::Fixed(64),
    range: Range::powers_of(2, 1.0, 4096.0),
};

pub const PARAMS: &[&dyn AnyParam] = &[&BASE];

/// The RSM quadtree level (mip) Basic ISR starts from.
pub fn base_level(s: &RenderSettings) -> u32 {
    s.rsm_top_level() - BASE.get(s).clamp(1, s.rsm_resolution).ilog2()
}

/// Base texels: at most one chosen patch each.
fn base_texels(s: &RenderSettings) -> u64 {
    let side = (s.rsm_resolution >> base_level(s)).max(1) as u64;
    side * side
}

pub struct IsrMethod;

impl Descriptor for IsrMethod {
    fn key(&self) -> Method {
        KEY
    }
    fn color(&self) -> [u8; 3] {
        [44, 160, 44]
    }
    fn help(&self) -> &'static str {
        "Basic ISR: per-frame clustered light patches, gathered by every eye patch."
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
        let (base, r) = (BASE.get(s), s.rsm_resolution);
        if base > r {
            bail!("--isr-base {base}: the base must be a power of 2 no larger than --rsm {r}");
        }
        Ok(())
    }
    /// The chosen list: at most one patch per base texel.
    fn memory(&self, s: &RenderSettings) -> u64 {
        base_texels(s) * std::mem::size_of::<LightPatch>() as u64
    }
    fn sweep(&self, rsm: u32, quick: bool) -> Vec<Params> {
        let bases: &[u32] = if quick { &[16, 64] } else { &[16, 32, 64] };
        bases
            .iter()
            .filter(|&&b| b <= rsm)
            .map(|&b| Params::new().with(&BASE, b))
            .collect()
    }
    fn label(&self, s: &RenderSettings) -> String {
        format!("base {}", BASE.get(s))
    }
    fn main_param(&self) -> Option<&'static dyn AnyParam> {
        Some(&BASE)
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        // At most one chosen patch per base texel, one invocation each.
        let base = base_level(setup.settings);
        let select = PatchList::new(
            setup,
            (
                "isr-select",
                "isr/select.comp",
                &[Spec::int("ISR_BASE_LEVEL", base as i32)],
            ),
            true,
            base_texels(setup.settings),
            setup.targets.rsm_position.mip_extent(base),
        )?;
        Ok(Box::new(MultiresMethod::gathering(
            setup,
            Box::new(select),
        )?))
    }
}
