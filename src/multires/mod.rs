//! The eye-space hierarchy of docs/algorithm.md section 3, the framework of
//! every method that works through it: geometry mipmaps, the layered
//! multiresolution illumination buffer with its layered stencil
//! ([`MultiresBuffer`]), the one-pass stenciled refinement, the gather
//! (`gather`) and the upsampling, around a method's light-space source
//! ([`LightSource`]) or its own fill pass ([`FillPass`]), put together by
//! [`MultiresMethod`]. The methods themselves live in `methods/`; no module
//! here names one.

mod buffer;
pub mod gather;
pub mod geometry_mips;
pub mod light_source;
pub mod method;
pub mod stencil_refine;
pub mod upsample;

pub use buffer::MultiresBuffer;
pub use light_source::{LightPatches, LightSource, PatchList};
pub use method::{FillPass, MultiresMethod};

use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{self, RunUniforms};
use crate::settings::params::{AnyParam, Choices, DefaultValue, Param, Range};
use crate::settings::RenderSettings;
use crate::vk::profiler::Profiler;
use anyhow::{bail, Result};

/// The largest number of levels the patch-count buffer holds.
pub const MAX_LEVELS: u32 = 16;

/// Coarsest level L (level l texels cover 2^l x 2^l pixels).
pub const LEVELS: Param<u32> = Param {
    name: "levels",
    help: "Coarsest level L of the multiresolution buffer (texels of 2^L x 2^L pixels)",
    default: DefaultValue::Derived(
        |s| default_levels(s.width, s.height),
        "about 1/16 of the shorter side: 5 at 512, 6 at 1024",
    ),
    range: Range::closed(1.0, (MAX_LEVELS - 1) as f64),
};

/// A texel is smooth when its view-depth range, relative to its nearest
/// depth, is below this: `(max - min) / min < t`.
pub const DEPTH_THRESHOLD: Param<f32> = Param {
    name: "depth-threshold",
    help: "Split a texel of the multiresolution buffer when its view-depth range relative \
           to its nearest depth, (max - min) / min, is not below this",
    default: DefaultValue::Fixed(0.1),
    range: Range::at_least(0.0),
};

/// ... and when the normals in it span less than this angle (degrees),
/// measured as the diagonal of their component-wise bounding box.
pub const NORMAL_THRESHOLD: Param<f32> = Param {
    name: "normal-threshold",
    help: "Split a texel of the multiresolution buffer when its normals span this angle \
           (degrees) or more",
    default: DefaultValue::Fixed(20.0),
    range: Range::closed(0.0, 180.0),
};

/// Upsampling of the multiresolution buffer to full resolution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Upsample {
    Interpolated,
    Nearest,
}

impl Choices for Upsample {
    const NAMES: &'static [(&'static str, &'static str)] = &[
        (
            "interpolated",
            "bilinear between neighbouring patches, renormalised, never across a discontinuity",
        ),
        (
            "nearest",
            "each pixel takes the value of the patch that covers it",
        ),
    ];
    fn index(self) -> usize {
        self as usize
    }
    fn from_index(i: usize) -> Self {
        [Upsample::Interpolated, Upsample::Nearest][i]
    }
}

pub const UPSAMPLE: Param<Upsample> = Param {
    name: "upsample",
    help: "Upsampling of the multiresolution buffer to full resolution",
    default: DefaultValue::Fixed(Upsample::Interpolated),
    range: Range::ANY,
};

/// Early stencil rejection in the gather (`false`: shade every texel of
/// every layer and mask afterwards, for measuring what the stencil saves).
pub const STENCIL: Param<bool> = Param {
    name: "stencil",
    help: "Early stencil rejection in the gather; off shades every texel of every level \
           and masks afterwards (to measure what the stencil saves)",
    default: DefaultValue::Fixed(true),
    range: Range::ANY,
};

/// The parameters of every method that works through the buffer.
pub const PARAMS: &[&dyn AnyParam] = &[
    &LEVELS,
    &DEPTH_THRESHOLD,
    &NORMAL_THRESHOLD,
    &UPSAMPLE,
    &STENCIL,
];

/// Coarsest level for a resolution: texels of level L are about 1/16 of the
/// shorter side (L = 5 at 512, 6 at 1024), at most 8.
pub fn default_levels(width: u32, height: u32) -> u32 {
    (width.min(height).max(2).ilog2().saturating_sub(4)).clamp(1, 8)
}

/// The checks across the hierarchy's parameters and the image size, for
/// `method` (after each parameter's own range).
pub fn check(s: &RenderSettings, method: &str) -> Result<()> {
    if s.width < 2 || s.height < 2 {
        bail!(
            "resolution {}x{}: method {method} needs at least 2x2 pixels (its multiresolution buffer's \
             coarsest level halves the image at least once); use a larger --width/--height, or a \
             full-resolution method (`isr render --help` says which methods read --levels)",
            s.width,
            s.height,
        );
    }
    let levels = LEVELS.get(s);
    if levels == 0 || levels >= MAX_LEVELS || s.width >> levels == 0 || s.height >> levels == 0 {
        let what = if LEVELS.is_set_in(s) {
            format!("--levels {levels}")
        } else {
            format!(
                "the default --levels ({levels}) for {}x{}",
                s.width, s.height
            )
        };
        bail!(
            "{what}: the coarsest level must be at least 1 and its texels ({0}x{0} pixels) no larger than the image; \
             choose a larger --width/--height or a smaller --levels",
            1u64 << levels.min(63)
        );
    }
    Ok(())
}

/// GPU memory of the buffer: (L + 1) layers of illumination (RGBA32F),
/// evaluation counts (R32F) and stencil, plus five geometry mip chains (four
/// RGBA32F, one R32UI).
pub fn memory(s: &RenderSettings) -> u64 {
    let pixels = s.width as u64 * s.height as u64;
    let layers = LEVELS.get(s).min(MAX_LEVELS) as u64 + 1;
    layers * pixels * (16 + 4 + 4) + pixels * 4 / 3 * (4 * 16 + 4)
}

/// The hierarchy's fields of the run uniforms.
pub fn write_uniforms(s: &RenderSettings, u: &mut RunUniforms) {
    u.levels = LEVELS.get(s) as i32;
    u.depth_threshold = DEPTH_THRESHOLD.get(s);
    u.normal_chord = 2.0 * (0.5 * NORMAL_THRESHOLD.get(s).to_radians()).sin();
    if !STENCIL.get(s) {
        u.hierarchy_flags |= gpu_types::HIERARCHY_STENCIL_OFF;
    }
}

/// The hierarchy's passes around a method's gather or splat: geometry mips and
/// stenciled refinement before it, upsampling after it.
pub struct Multires {
    pub buffer: MultiresBuffer,
    geometry_mips: geometry_mips::GeometryMipsPass,
    stencil_refine: stencil_refine::StencilRefinePass,
    upsample: upsample::UpsamplePass,
}

impl Multires {
    pub fn new(setup: &Setup) -> Result<Self> {
        let e = setup.targets.gbuffer_position.extent;
        let buffer = MultiresBuffer::new(setup.gpu, e.width, e.height, LEVELS.get(setup.settings))?;
        Ok(Self {
            geometry_mips: geometry_mips::GeometryMipsPass::new(setup, &buffer)?,
            stencil_refine: stencil_refine::StencilRefinePass::new(setup, &buffer)?,
            upsample: upsample::UpsamplePass::new(setup, &buffer)?,
            buffer,
        })
    }

    /// Geometry mips, then the stencil of patches.
    pub fn record_refinement(&self, ctx: &FrameContext, p: &mut Profiler) {
        self.geometry_mips.record(ctx, p, &self.buffer);
        self.stencil_refine.record(ctx, p, &self.buffer);
    }

    /// The illumination buffer to the full-resolution `indirect` image.
    pub fn record_upsample(&self, ctx: &FrameContext, p: &mut Profiler) {
        self.upsample.record(ctx, p, &self.buffer);
    }
}
