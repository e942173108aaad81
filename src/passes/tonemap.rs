//! Pass `tonemap`: exposure and sRGB encoding of `final_radiance` into the
//! 8-bit `display` image written as the PNG, `shaders/tonemap.frag`
//! (barriers: `FullscreenPass::record`).

use super::{FullscreenPass, GRAPHICS};
use crate::frame::Setup;
use crate::vk::pipeline::Binding;
use anyhow::Result;

pub fn new(setup: &Setup) -> Result<FullscreenPass> {
    let (t, s) = (setup.targets, setup.samplers);
    let bindings = [Binding::sampled(
        "final_radiance",
        t.final_radiance.view,
        s.nearest,
    )];
    FullscreenPass::new(
        setup,
        "tonemap",
        GRAPHICS,
        ("tonemap.frag", &[]),
        &bindings,
        0,
        |t| &t.display,
    )
}
