//! The eye-space hierarchy of docs/algorithm.md section 3: geometry mipmaps, the
//! layered multiresolution illumination buffer with its layered stencil, the
//! one-pass stenciled refinement and the upsampling. The methods that gather or
//! splat into the buffer live in `methods/`.

pub mod geometry_mips;
pub mod stencil_refine;
pub mod upsample;

use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{self, RunUniforms};
use crate::settings::params::{AnyParam, Choices, DefaultValue, Param, Range};
use crate::settings::RenderSettings;
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu, Image, ImageDesc};
use anyhow::{anyhow, bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

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

/// The images of the hierarchy. Geometry mips are mip chains holding levels
/// 1..=L (mip m is level m + 1, (W >> (m + 1)) x (H >> (m + 1))); level 0 is
/// the G-buffer itself (`shaders/multires/geo_levels.glsl`). The illumination buffer and
/// its stencil are 2D arrays with one W x H layer per level, layer l using
/// its corner.
pub struct MultiresBuffer {
    /// Coarsest level L; levels are 0..=L.
    pub levels: u32,
    pub geo_mean: Image,
    pub geo_normal: Image,
    pub geo_min: Image,
    pub geo_max: Image,
    pub geo_flags: Image,
    /// What the upsampling's push into level l - 1 reads of each level-l texel
    /// (l >= 1): its value and its relation to its neighbours, in layer l % 2
    /// (`multires/upsample.comp`, `store_tap`). Two layers of level 1's size.
    pub upsample_taps: Image,
    /// Irradiance E per patch (rgb) and the texel state in alpha (see `multires/upsample.glsl`).
    pub illumination: Image,
    /// Light patches each eye-space patch evaluated (a count in R32_SFLOAT, so
    /// splats can add it up; layered like the illumination buffer).
    pub evaluations: Image,
    pub stencil: Image,
    /// Patches per level, counted by the refinement (host-visible).
    pub patch_counts: Buffer,
}

impl MultiresBuffer {
    pub fn new(gpu: &Gpu, width: u32, height: u32, levels: u32) -> Result<Self> {
        let stencil_format = gpu
            .pick_format(
                &[
                    vk::Format::S8_UINT,
                    vk::Format::D24_UNORM_S8_UINT,
                    vk::Format::D32_SFLOAT_S8_UINT,
                ],
                vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT
                    | vk::FormatFeatureFlags::TRANSFER_SRC,
            )
            .ok_or_else(|| anyhow!("the device has no stencil format usable as an attachment"))?;
        // multires/geometry_mips.frag reads five storage images and writes five color
        // attachments (Vulkan guarantees four of each per fragment stage).
        let limits = gpu.limits();
        let (storage_images, colors, outputs) = (
            limits.max_per_stage_descriptor_storage_images,
            limits.max_color_attachments,
            limits.max_fragment_combined_output_resources,
        );
        if storage_images < 5 || colors < 5 || outputs < 10 {
            bail!(
                "{} allows {storage_images} storage images per stage, {colors} color attachments and \
                 {outputs} fragment output resources; the geometry mips need 5, 5 and 10. \
                 Choose another --device or --method none",
                gpu.info.name
            );
        }
        if !gpu.features.fragment_atomics {
            bail!(
                "{} lacks fragmentStoresAndAtomics, which the stenciled refinement needs; \
                 choose another --device or --method none",
                gpu.info.name
            );
        }
        if !gpu.features.shader_output_layer {
            bail!(
                "{} cannot choose the layer in a vertex shader (Vulkan 1.2 shaderOutputLayer), \
                 which the multiresolution buffer needs; choose another --device or --method",
                gpu.info.name
            );
        }
        let extent = vk::Extent2D { width, height };
        let storage = vk::ImageUsageFlags::STORAGE
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_SRC;
        let layered = |name, format, usage| {
            Image::new(
                gpu,
                &ImageDesc {
                    name,
                    format,
                    extent,
                    layers: levels + 1,
                    mips: 1,
                    usage,
                },
            )
        };
        // Every geometry-mip chain starts at level 1 (level 0 is the G-buffer,
        // `shaders/multires/geo_levels.glsl`): mip m of these chains is level m + 1.
        let chain = |name, format| {
            Image::new(
                gpu,
                &ImageDesc {
                    name,
                    format,
                    extent: vk::Extent2D {
                        width: width >> 1,
                        height: height >> 1,
                    },
                    layers: 1,
                    mips: levels,
                    // Written as attachments (multires/geometry_mips.glsl).
                    usage: storage | vk::ImageUsageFlags::COLOR_ATTACHMENT,
                },
            )
        };
        let rgba = vk::Format::R32G32B32A32_SFLOAT;
        Ok(Self {
            levels,
            geo_mean: chain("geo_mean", rgba)?,
            geo_normal: chain("geo_normal", rgba)?,
            geo_min: chain("geo_min", rgba)?,
            geo_max: chain("geo_max", rgba)?,
            geo_flags: chain("geo_flags", vk::Format::R32_UINT)?,
            upsample_taps: Image::new(
                gpu,
                &ImageDesc {
                    name: "upsample_taps",
                    format: rgba,
                    extent: vk::Extent2D {
                        width: (width >> 1).max(1),
                        height: (height >> 1).max(1),
                    },
                    layers: 2,
                    mips: 1,
                    usage: vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::SAMPLED,
                },
            )?,
            illumination: layered(
                "illumination",
                rgba,
                storage | vk::ImageUsageFlags::COLOR_ATTACHMENT,
            )?,
            evaluations: layered(
                "evaluations",
                vk::Format::R32_SFLOAT,
                vk::ImageUsageFlags::COLOR_ATTACHMENT
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::SAMPLED,
            )?,
            stencil: layered(
                "stencil",
                stencil_format,
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            )?,
            patch_counts: Buffer::new(
                gpu,
                "patch counts",
                4 * MAX_LEVELS as u64,
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?,
        })
    }

    /// Patches per level of the last counting frame (read once the device is
    /// idle: every counting frame writes this one buffer).
    pub fn patch_counts(&self) -> Vec<u32> {
        let mut counts: Vec<u32> = self.patch_counts.read_pod();
        counts.truncate(self.levels as usize + 1);
        counts
    }

    /// Texels in the used corners of all layers: what a gather without the
    /// stencil shades.
    pub fn total_area(&self) -> u64 {
        (0..=self.levels)
            .map(|l| {
                let e = self.level_extent(l);
                e.width as u64 * e.height as u64
            })
            .sum()
    }

    /// The used corner of level `l`: (W >> l) x (H >> l).
    pub fn level_extent(&self, l: u32) -> vk::Extent2D {
        let e = self.illumination.extent;
        vk::Extent2D {
            width: e.width >> l,
            height: e.height >> l,
        }
    }

    /// Records `draw` into every layer of the illumination buffer and the
    /// evaluation counts (both cleared to zero first), testing the stencil
    /// read-only when `stencil`; the barriers of the pass convention around it.
    /// The gather and the multiresolution splat fill the buffer this way.
    pub fn fill_layers(
        &self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        stencil: bool,
        draw: impl FnOnce(),
    ) {
        use crate::passes::{begin_rendering, Attachments, StencilAttachment};
        use crate::vk::barrier::{self, Use};
        let outputs = [&self.illumination, &self.evaluations];
        barrier::transition(
            gpu,
            cmd,
            &outputs,
            Use::DISCARD_AFTER_READERS,
            Use::COLOR_ATTACHMENT,
        );
        let colors = [self.illumination.view, self.evaluations.view];
        begin_rendering(
            gpu,
            cmd,
            &Attachments {
                extent: self.illumination.extent,
                layers: self.illumination.layers,
                colors: &colors,
                clear_colors: true,
                depth: None,
                stencil: stencil.then_some(StencilAttachment {
                    view: self.stencil.view,
                    clear: false,
                }),
            },
        );
        draw();
        unsafe { gpu.device.cmd_end_rendering(cmd) };
        barrier::transition(gpu, cmd, &outputs, Use::COLOR_ATTACHMENT, Use::READ_ONLY);
    }

    pub fn geometry_images(&self) -> [&Image; 5] {
        [
            &self.geo_mean,
            &self.geo_normal,
            &self.geo_min,
            &self.geo_max,
            &self.geo_flags,
        ]
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
