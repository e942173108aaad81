//! Method `none`: direct light only. The indirect image is cleared to zero
//! once, here, and no pass writes it afterwards.

use super::{Descriptor, IndirectMethod};
use crate::frame::{FrameContext, Setup};
use crate::settings::Method;
use crate::vk::barrier::{self, Use};
use crate::vk::profiler::Profiler;
use anyhow::Result;

pub const KEY: Method = Method::new("none");

pub struct NoneMethod;

impl Descriptor for NoneMethod {
    fn key(&self) -> Method {
        KEY
    }
    fn help(&self) -> &'static str {
        "Direct light only: indirect irradiance is zero."
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        Ok(Box::new(NoIndirect::new(setup)?))
    }
}

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
