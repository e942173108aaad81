//! Indirect-light methods, one module each (ALGORITHM.md sections 4 and 5).
//! Each writes the full-resolution indirect irradiance image: either through
//! the multiresolution buffer ([`gather::GatherMethod`]) or directly at full
//! resolution ([`FullResolution`]).

pub mod gather;
pub mod hisr;
pub mod isr;
pub mod multires_splat;
pub mod reference;
pub mod rsm_gather;
pub mod rsm_splat;

use crate::passes::FrameContext;
use crate::vk::profiler::Profiler;
use crate::vk::Gpu;

/// Methods that compute every pixel at full resolution.
pub enum FullResolution {
    Gather(rsm_gather::RsmGatherPass),
    Splat(rsm_splat::RsmSplatPass),
}

impl FullResolution {
    pub fn record(&self, ctx: &FrameContext, p: &mut Profiler) {
        match self {
            Self::Gather(g) => g.record(ctx, p),
            Self::Splat(s) => s.record(ctx, p),
        }
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        match self {
            Self::Gather(g) => g.destroy(gpu),
            Self::Splat(s) => s.destroy(gpu),
        }
    }
}
