//! Method `none`: direct light only. The indirect image is cleared to zero
//! once, here, and no pass writes it afterwards.

use super::IndirectMethod;
use crate::frame::{FrameContext, Setup};
use crate::vk::barrier::{self, Use};
use crate::vk::profiler::Profiler;
use anyhow::Result;

pub struct NoIndirect;

impl NoIndirect {
    pub fn new(setup: &Setup) -> Result<Self> {
        let (gpu, image) = (setup.gpu, &setup.targets.indirect);
        gpu.run_once(|cmd| barrier::clear_color(gpu, cmd, image, Use::READ_ONLY))?;
        Ok(Self)
    }
}

impl IndirectMethod for NoIndirect {
    fn record(&self, _: &FrameContext, _: &mut Profiler, _: usize) {}

    fn reads_rsm_tree(&self) -> bool {
        false
    }
}
