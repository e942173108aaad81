//! The images a frame writes (`Targets`, each written by exactly one pass)
//! and the samplers passes read them with.

use crate::settings::RenderSettings;
use crate::vk::{Gpu, Image, ImageDesc, Sampler};
use anyhow::Result;
use ash::vk;

/// RSM: position (xyz, area), normal (xyz, patch state), flux (rgb, solid angle).
pub const RSM_FORMATS: [vk::Format; 3] = [vk::Format::R32G32B32A32_SFLOAT; 3];
/// G-buffer: position (xyz, view depth), normal, albedo.
pub const GBUFFER_FORMATS: [vk::Format; 3] = [
    vk::Format::R32G32B32A32_SFLOAT,
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::R16G16B16A16_SFLOAT,
];
/// Radiance and irradiance images.
pub const HDR_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// The tonemap pass writes sRGB-encoded values itself, so the target is UNORM.
pub const DISPLAY_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

pub struct Targets {
    pub rsm_position: Image,
    pub rsm_normal: Image,
    pub rsm_flux: Image,
    pub rsm_depth: Image,
    pub gbuffer_position: Image,
    pub gbuffer_normal: Image,
    pub gbuffer_albedo: Image,
    pub gbuffer_depth: Image,
    pub direct: Image,
    /// Indirect irradiance E (W/m^2) at full resolution, written by the method.
    pub indirect: Image,
    pub final_radiance: Image,
    pub display: Image,
}

const COLOR_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::COLOR_ATTACHMENT.as_raw()
        | vk::ImageUsageFlags::SAMPLED.as_raw()
        | vk::ImageUsageFlags::TRANSFER_SRC.as_raw(),
);
const DEPTH_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
);
/// The RSM depth also receives a point light's cube face by copy (`rsm-face`).
const RSM_DEPTH_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    DEPTH_USAGE.as_raw() | vk::ImageUsageFlags::TRANSFER_DST.as_raw(),
);
/// RSM images carry the RSM quadtree in their mip chain (level 0 = the RSM);
/// a point light's cube faces are copied into level 0 (`rsm-face`).
const RSM_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    COLOR_USAGE.as_raw()
        | vk::ImageUsageFlags::STORAGE.as_raw()
        | vk::ImageUsageFlags::TRANSFER_DST.as_raw(),
);
/// `light-sum` adds light views' direct images in a compute shader.
const DIRECT_USAGE: vk::ImageUsageFlags =
    vk::ImageUsageFlags::from_raw(COLOR_USAGE.as_raw() | vk::ImageUsageFlags::STORAGE.as_raw());
/// Methods clear, blend into, or write `indirect` from compute.
const INDIRECT_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    COLOR_USAGE.as_raw()
        | vk::ImageUsageFlags::TRANSFER_DST.as_raw()
        | vk::ImageUsageFlags::STORAGE.as_raw(),
);

/// One target: its name, format, whether it is at RSM resolution (else at
/// the output resolution) and its usage.
pub struct TargetDesc {
    pub name: &'static str,
    pub format: vk::Format,
    pub at_rsm_resolution: bool,
    pub usage: vk::ImageUsageFlags,
}

/// Every target, in `Targets` order.
pub fn target_list() -> [TargetDesc; 12] {
    let t = |name, format, at_rsm_resolution, usage| TargetDesc {
        name,
        format,
        at_rsm_resolution,
        usage,
    };
    [
        t("rsm_position", RSM_FORMATS[0], true, RSM_USAGE),
        t("rsm_normal", RSM_FORMATS[1], true, RSM_USAGE),
        t("rsm_flux", RSM_FORMATS[2], true, RSM_USAGE),
        t("rsm_depth", DEPTH_FORMAT, true, RSM_DEPTH_USAGE),
        t("gbuffer_position", GBUFFER_FORMATS[0], false, COLOR_USAGE),
        t("gbuffer_normal", GBUFFER_FORMATS[1], false, COLOR_USAGE),
        t("gbuffer_albedo", GBUFFER_FORMATS[2], false, COLOR_USAGE),
        t("gbuffer_depth", DEPTH_FORMAT, false, DEPTH_USAGE),
        t("direct", HDR_FORMAT, false, DIRECT_USAGE),
        t("indirect", HDR_FORMAT, false, INDIRECT_USAGE),
        t("final", HDR_FORMAT, false, COLOR_USAGE),
        t("display", DISPLAY_FORMAT, false, COLOR_USAGE),
    ]
}

impl TargetDesc {
    /// Mip levels: RSM color images hold the whole quadtree.
    pub fn mips(&self, s: &RenderSettings) -> u32 {
        if self.at_rsm_resolution && self.format != DEPTH_FORMAT {
            s.rsm_top_level() + 1
        } else {
            1
        }
    }

    pub fn extent(&self, s: &RenderSettings) -> vk::Extent2D {
        if self.at_rsm_resolution {
            vk::Extent2D {
                width: s.rsm_resolution,
                height: s.rsm_resolution,
            }
        } else {
            vk::Extent2D {
                width: s.width,
                height: s.height,
            }
        }
    }
}

impl Targets {
    pub fn new(gpu: &Gpu, s: &RenderSettings) -> Result<Self> {
        let [a, b, c, d, e, f, g, h, i, j, k, l] = target_list();
        // Each image frees itself if a later one fails.
        let make = |t: TargetDesc| {
            Image::new(
                gpu,
                &ImageDesc {
                    name: t.name,
                    format: t.format,
                    extent: t.extent(s),
                    layers: 1,
                    mips: t.mips(s),
                    usage: t.usage,
                },
            )
        };
        Ok(Self {
            rsm_position: make(a)?,
            rsm_normal: make(b)?,
            rsm_flux: make(c)?,
            rsm_depth: make(d)?,
            gbuffer_position: make(e)?,
            gbuffer_normal: make(f)?,
            gbuffer_albedo: make(g)?,
            gbuffer_depth: make(h)?,
            direct: make(i)?,
            indirect: make(j)?,
            final_radiance: make(k)?,
            display: make(l)?,
        })
    }
}

pub struct Samplers {
    /// For `texelFetch` inputs (a combined image sampler needs some sampler).
    pub nearest: vk::Sampler,
    /// Hardware 2x2 PCF on reversed-Z depth: passes where reference >= stored.
    pub shadow: vk::Sampler,
    /// Scene textures (`texture_arrays`): bilinear, repeat at a layer's edges.
    pub texture: vk::Sampler,
    _owned: [Sampler; 3],
}

impl Samplers {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        let base = vk::SamplerCreateInfo::default()
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(0.0);
        let nearest = Sampler::new(gpu, &base)?;
        let shadow = Sampler::new(
            gpu,
            &base
                .mag_filter(vk::Filter::LINEAR)
                .min_filter(vk::Filter::LINEAR)
                .compare_enable(true)
                .compare_op(vk::CompareOp::GREATER_OR_EQUAL),
        )?;
        let texture = Sampler::new(
            gpu,
            &base
                .mag_filter(vk::Filter::LINEAR)
                .min_filter(vk::Filter::LINEAR)
                .address_mode_u(vk::SamplerAddressMode::REPEAT)
                .address_mode_v(vk::SamplerAddressMode::REPEAT),
        )?;
        Ok(Self {
            nearest: nearest.sampler,
            shadow: shadow.sampler,
            texture: texture.sampler,
            _owned: [nearest, shadow, texture],
        })
    }
}
