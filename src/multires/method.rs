//! The frame of every method that works through the multiresolution
//! buffer: [`MultiresMethod`] runs the eye-space refinement once per frame,
//! then per light view the method's light-space source (its passes, then the
//! gather of its light patches, `gather::GatherPass`) or the method's own
//! pass that fills the buffer ([`FillPass`]: the splat), and the upsampling.

use super::gather::GatherPass;
use super::{LightPatches, LightSource, Multires, MultiresBuffer};
use crate::frame::{FrameContext, Setup};
use crate::vk::profiler::Profiler;
use anyhow::Result;

/// What fills the multiresolution buffer's patches: the gather of a light
/// source, or a method's own pass (the splat).
pub trait FillPass {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer);
}

/// A method that works through the multiresolution buffer. Geometry mips and
/// stencil refinement once per frame (`record_eye_space`); per light view the
/// source's passes, the gather or the method's fill pass, then upsampling.
pub struct MultiresMethod {
    pub multires: Multires,
    source: Option<Box<dyn LightSource>>,
    fill: Box<dyn FillPass>,
}

impl MultiresMethod {
    /// A method that gathers the light patches of `source`.
    pub fn gathering(setup: &Setup, source: Box<dyn LightSource>) -> Result<Self> {
        let multires = Multires::new(setup)?;
        let fill = Box::new(GatherPass::new(setup, &multires.buffer, source.as_ref())?);
        Ok(Self {
            multires,
            source: Some(source),
            fill,
        })
    }

    /// A method whose own pass, made by `fill` for the buffer, fills it.
    pub fn filled_by(
        setup: &Setup,
        fill: impl FnOnce(&Setup, &MultiresBuffer) -> Result<Box<dyn FillPass>>,
    ) -> Result<Self> {
        let multires = Multires::new(setup)?;
        let fill = fill(setup, &multires.buffer)?;
        Ok(Self {
            multires,
            source: None,
            fill,
        })
    }

    /// Geometry mips and the stencil of patches, once per frame.
    pub fn record_eye_space(&self, ctx: &FrameContext, p: &mut Profiler) {
        self.multires.record_refinement(ctx, p);
    }

    /// One light view: the source's passes, the fill, the upsampling.
    pub fn record(&self, ctx: &FrameContext, p: &mut Profiler) {
        if let Some(source) = &self.source {
            source.record(ctx, p);
        }
        self.fill.record(ctx, p, &self.multires.buffer);
        self.multires.record_upsample(ctx, p);
    }

    pub fn buffer(&self) -> &MultiresBuffer {
        &self.multires.buffer
    }

    /// The source's light patches of the last frame, for a gathering method.
    pub fn light_patches(&self) -> Option<LightPatches<'_>> {
        self.source.as_ref().map(|s| s.light_patches())
    }
}
