//! Copying images and buffers back to the host, and the host-side images a
//! frame (or the CPU path tracer) produces. Regions are read by name and
//! decoded by name, so adding or reordering a region cannot shift the others.

use crate::frame::Targets;
use crate::gpu_types::{LightPatch, GEO_HAS_GEOMETRY, GEO_SMOOTH, LIGHT_PATCHES_HEADER};
use crate::multires::MultiresBuffer;
use crate::vk::barrier::{self, Use};
use crate::vk::resources::texel_bytes;
use crate::vk::{Buffer, Gpu, Image};
use anyhow::{anyhow, bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::collections::HashMap;

/// Image contents copied back to the host, rows top to bottom, RGBA f32.
#[derive(Clone, Debug)]
pub struct Readback {
    pub width: u32,
    pub height: u32,
    pub final_radiance: Vec<[f32; 4]>,
    pub direct: Vec<[f32; 4]>,
    pub indirect: Vec<[f32; 4]>,
    /// The indirect image's light by bounce where the renderer keeps it
    /// apart: the path tracer's layers (`bounces::LAYERS`: bounces 1, 2, 3,
    /// then 4 on), as many as its run traced, summing to `indirect`. Empty
    /// from the GPU, which renders one bounce.
    pub bounces: Vec<Vec<[f32; 4]>>,
    pub albedo: Vec<[f32; 4]>,
    pub normal: Vec<[f32; 4]>,
    /// xyz world position, w view depth (0 for background).
    pub position: Vec<[f32; 4]>,
    /// The tonemapped 8-bit sRGB image.
    pub display: Vec<u8>,
    pub rsm: RsmReadback,
}

#[derive(Clone, Debug)]
pub struct RsmReadback {
    pub resolution: u32,
    /// xyz position, w area A_j (0 where nothing was seen).
    pub position: Vec<[f32; 4]>,
    /// xyz normal, w patch state (`PATCH_*`).
    pub normal: Vec<[f32; 4]>,
    /// rgb flux Phi_j, a solid angle dw_j.
    pub flux: Vec<[f32; 4]>,
}

/// The multiresolution buffer copied back to the host (for tests and debug views).
pub struct MultiresReadback {
    pub width: u32,
    pub height: u32,
    pub levels: u32,
    /// Per layer l, the whole W x H layer (the used corner is (W >> l) x (H >> l)).
    pub illumination: Vec<Vec<[f32; 4]>>,
    /// Per layer l, light patches each texel evaluated (W x H).
    pub evaluations: Vec<Vec<u32>>,
    /// Per layer, stencil values, W x H.
    pub stencil: Vec<Vec<u8>>,
    /// Per mip level l, (W >> l) x (H >> l) texels.
    pub geo_mean: Vec<Vec<[f32; 4]>>,
    pub geo_normal: Vec<Vec<[f32; 4]>>,
    pub geo_flags: Vec<Vec<u32>>,
    /// RSM quadtree levels (level k is (R >> k)^2 texels): position, normal, flux.
    pub rsm_tree: Vec<[Vec<[f32; 4]>; 3]>,
}

/// Positions read back relative to the render origin (xyz; w holds
/// something else, and 0 where there is nothing) made world positions.
pub fn to_world(positions: &mut [[f32; 4]], origin: glam::DVec3) {
    if origin == glam::DVec3::ZERO {
        return;
    }
    for p in positions {
        if p[3] != 0.0 {
            let q = glam::Vec3::from_slice(&p[..3]).as_dvec3() + origin;
            p[..3].copy_from_slice(&q.as_vec3().to_array());
        }
    }
}

/// One mip level of one layer of an image, to copy to the host under `name`.
#[derive(Clone)]
pub struct Region<'a> {
    pub name: String,
    pub image: &'a Image,
    /// The image's resting state, restored after the copy.
    pub from: Use,
    pub mip: u32,
    pub layer: u32,
    /// COLOR, or STENCIL for the stencil of a depth/stencil image.
    pub aspect: vk::ImageAspectFlags,
}

impl<'a> Region<'a> {
    /// Mip `mip`, layer 0 of a color image in the `READ_ONLY` convention state.
    pub fn mip(name: impl Into<String>, image: &'a Image, mip: u32) -> Self {
        Self {
            name: name.into(),
            image,
            from: Use::READ_ONLY,
            mip,
            layer: 0,
            aspect: vk::ImageAspectFlags::COLOR,
        }
    }

    pub fn color(name: impl Into<String>, image: &'a Image) -> Self {
        Self::mip(name, image, 0)
    }

    pub fn layer(name: impl Into<String>, image: &'a Image, layer: u32) -> Self {
        Self {
            layer,
            ..Self::color(name, image)
        }
    }

    fn bytes(&self) -> u64 {
        let e = self.image.mip_extent(self.mip);
        let texel = if self.aspect == vk::ImageAspectFlags::STENCIL {
            1
        } else {
            texel_bytes(self.image.format)
        };
        e.width as u64 * e.height as u64 * texel
    }
}

/// What `read_regions` returns: each region's bytes and format, by name.
pub struct Regions(HashMap<String, (Vec<u8>, vk::Format)>);

impl Regions {
    /// The bytes of region `name`.
    pub fn bytes(&mut self, name: &str) -> Result<Vec<u8>> {
        self.0
            .remove(name)
            .map(|(b, _)| b)
            .ok_or_else(|| anyhow!("no region named {name} was read back"))
    }

    /// Region `name` as RGBA f32 (from RGBA32F or RGBA16F).
    pub fn rgba(&mut self, name: &str) -> Result<Vec<[f32; 4]>> {
        let (bytes, format) = self
            .0
            .remove(name)
            .ok_or_else(|| anyhow!("no region named {name} was read back"))?;
        to_rgba_f32(&bytes, format)
    }

    /// Region `name` as 32-bit words.
    pub fn words(&mut self, name: &str) -> Result<Vec<u32>> {
        Ok(bytemuck::pod_collect_to_vec(&self.bytes(name)?))
    }
}

/// Copies `regions` into host memory in one submission; each image is back in
/// its resting state afterwards.
pub fn read_regions(gpu: &Gpu, regions: &[Region]) -> Result<Regions> {
    let buffers = regions
        .iter()
        .map(|r| {
            Buffer::new(
                gpu,
                "readback",
                r.bytes(),
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )
        })
        .collect::<Result<Vec<_>>>()?;
    // One transition per image, however many of its regions are read.
    let mut images: Vec<(&Image, Use)> = Vec::new();
    for r in regions {
        if !images.iter().any(|(i, _)| i.image == r.image.image) {
            images.push((r.image, r.from));
        }
    }
    gpu.run_once(|cmd| unsafe {
        let to_src: Vec<_> = images
            .iter()
            .map(|(i, from)| barrier::image(i, *from, Use::TRANSFER_SRC))
            .collect();
        barrier::images(gpu, cmd, &to_src);
        for (r, buf) in regions.iter().zip(&buffers) {
            let e = r.image.mip_extent(r.mip);
            let region = vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: r.aspect,
                    mip_level: r.mip,
                    base_array_layer: r.layer,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D {
                    width: e.width,
                    height: e.height,
                    depth: 1,
                });
            gpu.device.cmd_copy_image_to_buffer(
                cmd,
                r.image.image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buf.buffer,
                &[region],
            );
        }
        let back: Vec<_> = images
            .iter()
            .map(|(i, from)| barrier::image(i, Use::TRANSFER_SRC, *from))
            .collect();
        barrier::images(gpu, cmd, &back);
        barrier::copies_to_host(gpu, cmd);
    })?;
    let mut out = HashMap::new();
    for (r, b) in regions.iter().zip(&buffers) {
        if out
            .insert(r.name.clone(), (b.mapped().to_vec(), r.image.format))
            .is_some()
        {
            bail!("two readback regions are named {}", r.name);
        }
    }
    Ok(Regions(out))
}

/// Copies a device-local buffer to the host (after the frames that wrote it).
pub fn read_buffer(gpu: &Gpu, buffer: &Buffer) -> Result<Vec<u8>> {
    let staging = Buffer::new(
        gpu,
        "readback",
        buffer.size,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?;
    gpu.run_once(|cmd| unsafe {
        gpu.device.cmd_copy_buffer(
            cmd,
            buffer.buffer,
            staging.buffer,
            &[vk::BufferCopy::default().size(buffer.size)],
        );
        barrier::copies_to_host(gpu, cmd);
    })?;
    Ok(staging.mapped().to_vec())
}

fn to_rgba_f32(bytes: &[u8], format: vk::Format) -> Result<Vec<[f32; 4]>> {
    Ok(match format {
        vk::Format::R32G32B32A32_SFLOAT => bytemuck::pod_collect_to_vec(bytes),
        vk::Format::R16G16B16A16_SFLOAT => {
            bytemuck::pod_collect_to_vec::<u8, [half::f16; 4]>(bytes)
                .into_iter()
                .map(|p| p.map(half::f16::to_f32))
                .collect()
        }
        other => bail!("readback of {other:?} as f32 is not implemented"),
    })
}

/// Every output of the last frame.
pub fn read_frame(gpu: &Gpu, t: &Targets) -> Result<Readback> {
    let regions = [
        Region::color("final", &t.final_radiance),
        Region::color("direct", &t.direct),
        Region::color("indirect", &t.indirect),
        Region::color("albedo", &t.gbuffer_albedo),
        Region::color("normal", &t.gbuffer_normal),
        Region::color("position", &t.gbuffer_position),
        Region::color("display", &t.display),
        Region::color("rsm_position", &t.rsm_position),
        Region::color("rsm_normal", &t.rsm_normal),
        Region::color("rsm_flux", &t.rsm_flux),
    ];
    let mut r = read_regions(gpu, &regions)?;
    Ok(Readback {
        width: t.final_radiance.extent.width,
        height: t.final_radiance.extent.height,
        final_radiance: r.rgba("final")?,
        direct: r.rgba("direct")?,
        indirect: r.rgba("indirect")?,
        bounces: vec![],
        albedo: r.rgba("albedo")?,
        normal: r.rgba("normal")?,
        position: r.rgba("position")?,
        display: r.bytes("display")?,
        rsm: RsmReadback {
            resolution: t.rsm_position.extent.width,
            position: r.rgba("rsm_position")?,
            normal: r.rgba("rsm_normal")?,
            flux: r.rgba("rsm_flux")?,
        },
    })
}

/// The multiresolution buffer `m` and the RSM quadtree of the last frame.
pub fn read_multires(gpu: &Gpu, m: &MultiresBuffer, t: &Targets) -> Result<MultiresReadback> {
    let n = m.levels + 1;
    let mut regions = Vec::new();
    for l in 0..n {
        regions.push(Region::layer(
            format!("illumination/{l}"),
            &m.illumination,
            l,
        ));
        regions.push(Region::layer(format!("evaluations/{l}"), &m.evaluations, l));
        regions.push(Region {
            from: Use::STENCIL_READ_ONLY,
            aspect: vk::ImageAspectFlags::STENCIL,
            ..Region::layer(format!("stencil/{l}"), &m.stencil, l)
        });
        if l > 0 {
            regions.push(Region::mip(format!("geo_mean/{l}"), &m.geo_mean, l - 1));
            regions.push(Region::mip(format!("geo_normal/{l}"), &m.geo_normal, l - 1));
            regions.push(Region::mip(format!("geo_flags/{l}"), &m.geo_flags, l - 1));
        }
    }
    // Level 0 of the mean and normal is the G-buffer (`shaders/multires/geo_levels.glsl`).
    regions.push(Region::mip("gbuffer_position", &t.gbuffer_position, 0));
    regions.push(Region::mip("gbuffer_normal", &t.gbuffer_normal, 0));
    let rsm_levels = t.rsm_position.mips;
    for k in 0..rsm_levels {
        regions.push(Region::mip(format!("rsm_position/{k}"), &t.rsm_position, k));
        regions.push(Region::mip(format!("rsm_normal/{k}"), &t.rsm_normal, k));
        regions.push(Region::mip(format!("rsm_flux/{k}"), &t.rsm_flux, k));
    }
    let mut r = read_regions(gpu, &regions)?;
    let per_level = |r: &mut Regions, name: &str| -> Result<Vec<Vec<[f32; 4]>>> {
        (0..n).map(|l| r.rgba(&format!("{name}/{l}"))).collect()
    };
    let illumination = per_level(&mut r, "illumination")?;
    let level0_mean = r.rgba("gbuffer_position")?;
    // As `level0_normal` in the shader: renormalised, coverage 1 with geometry.
    let level0_normal: Vec<[f32; 4]> = r
        .rgba("gbuffer_normal")?
        .iter()
        .zip(&level0_mean)
        .map(|(n, p)| {
            if p[3] <= 0.0 {
                return [0.0; 4];
            }
            let v = glam::Vec3::new(n[0], n[1], n[2]).normalize();
            [v.x, v.y, v.z, 1.0]
        })
        .collect();
    let mut above = |name: &str| -> Result<Vec<Vec<[f32; 4]>>> {
        (1..n).map(|l| r.rgba(&format!("{name}/{l}"))).collect()
    };
    let geo_mean: Vec<_> = std::iter::once(level0_mean)
        .chain(above("geo_mean")?)
        .collect();
    let geo_normal: Vec<_> = std::iter::once(level0_normal)
        .chain(above("geo_normal")?)
        .collect();
    // Counts are stored as f32 (exact below 2^24) so that splats can add them.
    let evaluations = (0..n)
        .map(|l| {
            let floats: Vec<f32> =
                bytemuck::pod_collect_to_vec(&r.bytes(&format!("evaluations/{l}"))?);
            Ok(floats.into_iter().map(|f| f as u32).collect())
        })
        .collect::<Result<Vec<Vec<u32>>>>()?;
    let stencil = (0..n)
        .map(|l| r.bytes(&format!("stencil/{l}")))
        .collect::<Result<Vec<_>>>()?;
    // Level 0 is always smooth where there is geometry (`geo_flags_at`).
    let level0_flags = geo_mean[0]
        .iter()
        .map(|p| {
            if p[3] > 0.0 {
                GEO_HAS_GEOMETRY | GEO_SMOOTH
            } else {
                0
            }
        })
        .collect();
    let geo_flags = std::iter::once(Ok(level0_flags))
        .chain((1..n).map(|l| r.words(&format!("geo_flags/{l}"))))
        .collect::<Result<Vec<_>>>()?;
    let rsm_tree = (0..rsm_levels)
        .map(|k| {
            Ok([
                r.rgba(&format!("rsm_position/{k}"))?,
                r.rgba(&format!("rsm_normal/{k}"))?,
                r.rgba(&format!("rsm_flux/{k}"))?,
            ])
        })
        .collect::<Result<Vec<_>>>()?;
    let e = m.illumination.extent;
    Ok(MultiresReadback {
        width: e.width,
        height: e.height,
        levels: m.levels,
        illumination,
        evaluations,
        stencil,
        geo_mean,
        geo_normal,
        geo_flags,
        rsm_tree,
    })
}

/// The light patches in `buffer` (header, then the list: `multires::LightPatches`).
pub fn read_light_patches(gpu: &Gpu, buffer: &Buffer) -> Result<Vec<LightPatch>> {
    let bytes = read_buffer(gpu, buffer)?;
    let size = std::mem::size_of::<LightPatch>();
    let count = u32::from_le_bytes(bytes[..4].try_into()?) as usize;
    // Clamped to the capacity: before any frame the count is not yet written.
    let capacity = (bytes.len() - LIGHT_PATCHES_HEADER) / size;
    let end = LIGHT_PATCHES_HEADER + count.min(capacity) * size;
    Ok(bytemuck::pod_collect_to_vec(
        &bytes[LIGHT_PATCHES_HEADER..end],
    ))
}
