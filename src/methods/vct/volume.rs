//! The radiance volume on the GPU (docs/algorithm.md section 9): its
//! buffer, images and pipelines, and the passes each light view records.
//!
//! - `vct-inject`: `vct/inject.comp`, one invocation per RSM texel, adds its
//!   flux, area and flux-weighted normal to its cell's sums with integer
//!   atomics (fixed point: the sums do not depend on the order texels come
//!   in, so the volume is the same every run).
//! - `vct-mips`: `vct/mips.comp`, one dispatch per level: level 0 turns each
//!   cell's sums and the surface in it (`voxel-surface`) into premultiplied
//!   radiance and opacity and two lobes (which way its lit surface and its
//!   surface face); each further level composites the opacity of the 8
//!   cells under it along each axis and keeps the others' means.
//! - `vct-trace`: `fullscreen.vert` + `vct/trace.frag` trace the cones
//!   through the volumes (hardware trilinear between cells and mips) and
//!   write `indirect`.
//!
//! The volumes are 3D images, written as storage images (the grid is small:
//! a 64^3 level is 262,144 stores) and sampled with a trilinear, mipmapped
//! sampler. Barriers are written beside the commands they guard.

use super::Layout;
use crate::frame::{FrameContext, Setup};
use crate::methods::IndirectMethod;
use crate::passes::{push_bytes, ComputePass, FullscreenPass, INDIRECT_COMPUTE, INDIRECT_GRAPHICS};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Image, ImageDesc, Sampler};
use anyhow::{anyhow, bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Words of the injection sums per cell (`shaders/vct/vct.glsl`): flux
/// (RGB), area, flux-weighted normal (xyz), unused.
pub const ACCUM_WORDS: usize = 8;

/// Both volumes: RGBA32F (radiance in W/(m^2 sr) can pass half-float's range).
pub const VOLUME_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

/// Method `vct`'s GPU objects for a run; they free themselves when dropped.
pub struct Vct {
    layout: Layout,
    accum: Buffer,
    /// Premultiplied radiance (rgb) and opacity (a), every level.
    radiance: Image,
    /// The emission lobe: the mean normal of the lit surface times the
    /// luminance of `radiance` (xyz), and that luminance (w), every level.
    lobe: Image,
    /// The surface's lobe: its mean normal times opacity (xyz), and
    /// opacity (w), every level.
    surface: Image,
    _sampler: Sampler,
    rsm_texels: u32,
    inject: ComputePass,
    mips: ComputePass,
    trace: FullscreenPass,
}

impl Vct {
    pub fn new(setup: &Setup) -> Result<Self> {
        let gpu = setup.gpu;
        let s = setup.settings;
        let layout = Layout::of(s);
        let surface = setup.grid_surface.ok_or_else(|| {
            anyhow!(
                "method vct reads the surface in the voxel grid's cells, which this run did \
                 not make; start the run with --method vct"
            )
        })?;
        let needed = vk::FormatFeatureFlags::STORAGE_IMAGE
            | vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR;
        if gpu.pick_format(&[VOLUME_FORMAT], needed).is_none() {
            bail!(
                "{} cannot filter or store {VOLUME_FORMAT:?} images, which method vct's \
                 radiance volumes are; choose another method",
                gpu.info.name
            );
        }
        let n = layout.side;
        let volume = |name: &str| {
            Image::volume(
                gpu,
                &ImageDesc {
                    name,
                    format: VOLUME_FORMAT,
                    extent: vk::Extent2D {
                        width: n,
                        height: n,
                    },
                    layers: 1,
                    mips: layout.levels,
                    usage: vk::ImageUsageFlags::STORAGE
                        | vk::ImageUsageFlags::SAMPLED
                        | vk::ImageUsageFlags::TRANSFER_SRC,
                },
                n,
            )
        };
        let radiance = volume("vct radiance")?;
        let lobe = volume("vct lobe")?;
        let surface_lobe = volume("vct surface lobe")?;
        let accum = Buffer::new(
            gpu,
            "vct injection sums",
            layout.cells() * ACCUM_WORDS as u64 * 4,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        // Trilinear between cells and between mips. Clamped to the edge: the
        // grid's cube is the scene's bounds, so a coarse level's edge cells
        // hold the walls there, and an empty border blended in would make
        // them transparent wherever a sample is nearer the edge than the
        // cells' centres (at the coarsest levels, nearly everywhere).
        let sampler = Sampler::new(
            gpu,
            &vk::SamplerCreateInfo::default()
                .mag_filter(vk::Filter::LINEAR)
                .min_filter(vk::Filter::LINEAR)
                .mipmap_mode(vk::SamplerMipmapMode::LINEAR)
                .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .max_lod((layout.levels - 1) as f32),
        )?;

        let (t, nearest) = (setup.targets, setup.samplers.nearest);
        let size = Spec::int("VCT_SIZE", n as i32);
        let inject = ComputePass::new(
            setup,
            "vct-inject",
            "vct/inject.comp",
            &[vec![
                Binding::sampled("rsm_position", t.rsm_position.view, nearest),
                Binding::sampled("rsm_normal", t.rsm_normal.view, nearest),
                Binding::sampled("rsm_flux", t.rsm_flux.view, nearest),
                Binding::storage("VctAccum", &accum),
            ]],
            0,
            &[size],
        )?;
        let level = |k: usize| {
            let from = k.saturating_sub(1);
            vec![
                Binding::storage("GridSurface", surface),
                Binding::storage("VctAccum", &accum),
                Binding::storage_image("source_radiance", radiance.mip_views[from]),
                Binding::storage_image("source_lobe", lobe.mip_views[from]),
                Binding::storage_image("source_surface", surface_lobe.mip_views[from]),
                Binding::storage_image("target_radiance", radiance.mip_views[k]),
                Binding::storage_image("target_lobe", lobe.mip_views[k]),
                Binding::storage_image("target_surface", surface_lobe.mip_views[k]),
            ]
        };
        let variants: Vec<Vec<Binding>> = (0..layout.levels as usize).map(level).collect();
        let mips = ComputePass::new(setup, "vct-mips", "vct/mips.comp", &variants, 4, &[size])?;
        let trace = FullscreenPass::new(
            setup,
            "vct-trace",
            INDIRECT_GRAPHICS,
            (
                "vct/trace.frag",
                &[
                    size,
                    Spec::int("VCT_LEVELS", layout.levels as i32),
                    Spec::int("VCT_CONES", layout.cones as i32),
                    Spec::bool("VCT_LOBE", layout.lobe),
                    Spec::float(
                        "VCT_RING_TAN",
                        super::cones::ring_half_angle(layout.cones).tan() as f32,
                    ),
                ],
            ),
            &[
                Binding::sampled("gbuffer_position", t.gbuffer_position.view, nearest),
                Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, nearest),
                Binding::sampled("vct_radiance", radiance.view, sampler.sampler),
                Binding::sampled("vct_lobe", lobe.view, sampler.sampler),
                Binding::sampled("vct_surface", surface_lobe.view, sampler.sampler),
            ],
            0,
            |t| &t.indirect,
        )?;
        Ok(Self {
            layout,
            accum,
            radiance,
            lobe,
            surface: surface_lobe,
            _sampler: sampler,
            rsm_texels: s.rsm_resolution,
            inject,
            mips,
            trace,
        })
    }

    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// The injection sums of the last light view (`ACCUM_WORDS` words a cell).
    pub fn sums(&self) -> &Buffer {
        &self.accum
    }

    /// The radiance and opacity volume of the last light view, its lit
    /// lobe and its surface lobe (read-only between frames).
    pub fn volumes(&self) -> [&Image; 3] {
        [&self.radiance, &self.lobe, &self.surface]
    }
}

impl IndirectMethod for Vct {
    fn reads_rsm_tree(&self) -> bool {
        false
    }

    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, _: usize) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let l = self.layout;
        let rw = vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
        profiler.pass(gpu, cmd, "vct-inject", INDIRECT_COMPUTE, || {
            // The previous view's level 0 (and readbacks) before the clear;
            // the clear before the atomics.
            barrier::zero_buffer(
                gpu,
                cmd,
                self.accum.buffer,
                self.accum.size,
                (barrier::READERS, vk::AccessFlags2::NONE),
                (vk::PipelineStageFlags2::COMPUTE_SHADER, rw),
            );
            let r = self.rsm_texels;
            self.inject.dispatch(
                ctx,
                0,
                &[],
                vk::Extent2D {
                    width: r,
                    height: r,
                },
            );
            // The atomics before level 0 reads the sums.
            barrier::compute_to_compute(gpu, cmd);
        });
        let volumes = self.volumes();
        profiler.pass(gpu, cmd, "vct-mips", INDIRECT_COMPUTE, || {
            // Discard: the previous view's trace (and readbacks) are done first.
            barrier::transition(
                gpu,
                cmd,
                &volumes,
                Use::DISCARD_AFTER_READERS,
                Use::COMPUTE_STORAGE,
            );
            for k in 0..l.levels {
                if k > 0 {
                    // Level k reads level k - 1's stores.
                    barrier::compute_to_compute(gpu, cmd);
                }
                let m = l.side >> k;
                self.mips.dispatch(
                    ctx,
                    k as usize,
                    &push_bytes(&[k as i32]),
                    vk::Extent2D {
                        width: m,
                        height: m * m,
                    },
                );
            }
            barrier::transition(gpu, cmd, &volumes, Use::COMPUTE_STORAGE, Use::READ_ONLY);
        });
        self.trace.record(ctx, profiler);
    }
}
