//! Pass `composite`: final radiance = direct + albedo/pi * indirect irradiance
//! (docs/algorithm.md section 2), `shaders/composite.frag`. Reads `direct`,
//! `gbuffer_albedo`, `indirect`; writes `final_radiance` (barriers: `FullscreenPass::record`).

use super::{FullscreenPass, GRAPHICS};
use crate::frame::Setup;
use crate::vk::pipeline::Binding;
use anyhow::Result;

pub fn new(setup: &Setup) -> Result<FullscreenPass> {
    let (t, s) = (setup.targets, setup.samplers);
    let bindings = [
        Binding::sampled("direct_radiance", t.direct.view, s.nearest),
        Binding::sampled("gbuffer_albedo", t.gbuffer_albedo.view, s.nearest),
        Binding::sampled("indirect_irradiance", t.indirect.view, s.nearest),
    ];
    FullscreenPass::new(
        setup,
        "composite",
        GRAPHICS,
        ("composite.frag", &[]),
        &bindings,
        0,
        |t| &t.final_radiance,
    )
}
