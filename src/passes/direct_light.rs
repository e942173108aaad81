//! Pass `direct`: direct radiance from the light view with PCF on the
//! shadow map of pass `shadow` (docs/algorithm.md section 2.2),
//! `shaders/direct_light.frag`. Reads the G-buffer and the shadow map;
//! writes `direct` (barriers: `FullscreenPass::record`).

use super::{FullscreenPass, GRAPHICS};
use crate::frame::Setup;
use crate::vk::pipeline::Binding;
use crate::vk::Image;
use anyhow::Result;

/// `shadow`: the shadow map (`shadow::ShadowPass::depth`).
pub fn new(setup: &Setup, shadow: &Image) -> Result<FullscreenPass> {
    let (t, s) = (setup.targets, setup.samplers);
    let bindings = [
        Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
        Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
        Binding::sampled("gbuffer_albedo", t.gbuffer_albedo.view, s.nearest),
        Binding::sampled("shadow_depth", shadow.view, s.shadow),
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
