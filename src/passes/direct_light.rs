//! Pass `direct`: direct radiance from the spot light with the RSM depth as a
//! PCF shadow map (docs/algorithm.md section 2), `shaders/direct_light.frag`.
//! Reads the G-buffer and `rsm_depth`; writes `direct` (barriers: `FullscreenPass::record`).

use super::{FullscreenPass, GRAPHICS};
use crate::frame::Setup;
use crate::vk::pipeline::Binding;
use anyhow::Result;

pub fn new(setup: &Setup) -> Result<FullscreenPass> {
    let (t, s) = (setup.targets, setup.samplers);
    let bindings = [
        Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
        Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
        Binding::sampled("gbuffer_albedo", t.gbuffer_albedo.view, s.nearest),
        Binding::sampled("rsm_depth", t.rsm_depth.view, s.shadow),
    ];
    FullscreenPass::new(
        setup,
        "direct",
        GRAPHICS,
        ("direct_light.frag", &[]),
        &bindings,
        0,
        |t| &t.direct,
    )
}
