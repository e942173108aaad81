//! Indirect-light methods, one module each (docs/algorithm.md sections 4 and
//! 5), behind one interface, [`IndirectMethod`]: each writes the
//! full-resolution indirect irradiance image `Targets::indirect`, either
//! through the multiresolution buffer ([`gather::MultiresMethod`]) or directly
//! at full resolution.
//!
//! Adding a method: its module here (and its shaders), a variant of
//! `settings::Method` (its doc comment is the CLI help), and one arm in
//! [`create`].

pub mod gather;
pub mod hisr;
pub mod isr;
pub mod multires_gather;
pub mod multires_splat;
pub mod none;
pub mod reference;
pub mod rsm_gather;
pub mod rsm_splat;

use crate::frame::{FrameContext, Setup};
use crate::multires::MultiresBuffer;
use crate::settings::Method;
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::{bail, Result};

/// One way of computing indirect light. Made once per run (`create`); records
/// its passes into every frame after the RSM, G-buffer, direct light and (if
/// it reads it) the RSM quadtree, once per light view, and before the
/// composite. Its GPU objects
/// free themselves when it is dropped.
pub trait IndirectMethod {
    /// Command buffers one frame of the method takes: the reference splits its
    /// work so that no submission runs long enough to trip a driver timeout.
    fn submissions(&self) -> usize {
        1
    }

    /// Records the passes that depend on the camera alone (the eye-space
    /// refinement), once per frame after the G-buffer: a frame with several
    /// light views (point-light faces, several lights) shares them.
    fn record_eye_space(&self, _ctx: &FrameContext, _profiler: &mut Profiler) {}

    /// Records submission `submission` (of `submissions()`) of one light view
    /// into `ctx.cmd`. After the last one, `indirect` is written and in the
    /// `READ_ONLY` state.
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, submission: usize);

    /// Whether the frame must build the RSM quadtree (`passes::rsm_tree`) first.
    fn reads_rsm_tree(&self) -> bool {
        true
    }

    /// The multiresolution buffer, for the methods that fill one.
    fn multires(&self) -> Option<&MultiresBuffer> {
        None
    }

    /// Basic ISR's list of chosen light patches (`CHOSEN_PATCHES_HEADER`, then
    /// `LightPatch`es).
    fn chosen_patches(&self) -> Option<&Buffer> {
        None
    }

    /// HISR's packed light tree (`CHOSEN_PATCHES_HEADER`, then a `LightPatch`
    /// per quadtree node, root first; see `shaders/light_tree_pack.comp`).
    fn packed_light_tree(&self) -> Option<&Buffer> {
        None
    }
}

/// The method `setup.settings.method` names, made for `setup`.
pub fn create(setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
    Ok(match setup.settings.method {
        Method::None => Box::new(none::NoIndirect::new(setup)?),
        Method::MultiresGather => Box::new(multires_gather::new(setup)?),
        Method::Isr => Box::new(isr::new(setup)?),
        Method::Hisr => Box::new(hisr::new(setup)?),
        Method::RsmGather => Box::new(rsm_gather::RsmGather::new(setup)?),
        Method::RsmSplat => Box::new(rsm_splat::RsmSplat::new(setup, false)?),
        Method::RsmSplatRestricted => Box::new(rsm_splat::RsmSplat::new(setup, true)?),
        Method::MultiresSplat => Box::new(multires_splat::new(setup)?),
        Method::Reference => Box::new(reference::Reference::new(setup)?),
        Method::Pathtrace => bail!(
            "method pathtrace runs on the CPU (isr::pathtrace::render), not in the Vulkan renderer"
        ),
    })
}
