//! Method `rsm-gather` (docs/algorithm.md section 5, Dachsbacher & Stamminger
//! 2005): every full-resolution pixel gathers the N regular VPLs. Pass
//! `rsm-gather`, `shaders/rsm_gather/gather.frag` (barriers: `FullscreenPass::record`).
//! Reads the G-buffer and the RSM quadtree; writes `indirect`.

use super::{Descriptor, IndirectMethod};
use crate::frame::{FrameContext, Setup};
use crate::passes::{push_bytes, FullscreenPass, INDIRECT_GRAPHICS};
use crate::regular_vpls::RegularVpls;
use crate::settings::{Method, RenderSettings};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use anyhow::Result;

pub const KEY: Method = Method::new("rsm-gather");

pub struct RsmGatherMethod;

impl Descriptor for RsmGatherMethod {
    fn key(&self) -> Method {
        KEY
    }
    fn color(&self) -> [u8; 3] {
        [120, 120, 120]
    }
    fn help(&self) -> &'static str {
        "Every full-resolution pixel gathers N regular VPLs."
    }
    fn reads_regular_vpls(&self) -> bool {
        true
    }
    fn reads_visibility(&self) -> bool {
        true
    }
    fn evaluations_per_pixel(&self, s: &RenderSettings) -> Option<u64> {
        Some(RegularVpls::of(s).count as u64)
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        Ok(Box::new(RsmGather::new(setup)?))
    }
}

/// The bindings `rsm_gather/gather.frag` and the splat shaders share: G-buffer
/// position and normal, RSM quadtree position, normal and flux.
pub fn full_resolution_bindings<'a>(setup: &Setup<'a>) -> Vec<Binding<'a>> {
    let (t, s) = (setup.targets, setup.samplers);
    vec![
        Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
        Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
        Binding::sampled("rsm_position", t.rsm_position.view, s.nearest),
        Binding::sampled("rsm_normal", t.rsm_normal.view, s.nearest),
        Binding::sampled("rsm_flux", t.rsm_flux.view, s.nearest),
    ]
}

pub struct RsmGather(FullscreenPass);

impl RsmGather {
    pub fn new(setup: &Setup) -> Result<Self> {
        Ok(Self(FullscreenPass::new(
            setup,
            "rsm-gather",
            INDIRECT_GRAPHICS,
            (
                "rsm_gather/gather.frag",
                &[
                    &crate::visibility::specialization(setup.settings)[..],
                    &RegularVpls::of(setup.settings).specialization(setup.settings),
                ]
                .concat(),
            ),
            &full_resolution_bindings(setup),
            8,
            |t| &t.indirect,
        )?))
    }
}

impl IndirectMethod for RsmGather {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, _: usize) {
        // All VPLs: first 0, last past the end.
        self.0
            .record_with(ctx, profiler, &push_bytes(&[0, i32::MAX]));
    }
}
