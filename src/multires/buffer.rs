//! The images of the eye-space hierarchy (docs/algorithm.md section 3): the
//! geometry mips, the layered illumination buffer with its layered stencil,
//! the evaluation counts and the upsampling's taps.

use super::MAX_LEVELS;
use crate::vk::{Buffer, Gpu, Image, ImageDesc};
use anyhow::{anyhow, bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

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
