//! The propagation volume on the GPU (docs/algorithm.md section 8): its
//! images, buffers and pipelines, and the passes each light view records.
//!
//! - `lpv-geometry` (once per frame, camera only; with `--lpv-occlusion`):
//!   `lpv/geometry.vert/.frag` splat the G-buffer's surfels' blocking
//!   potentials into the eye geometry volume.
//! - `lpv-inject` (per view): `lpv/inject.vert/.frag` splat the RSM's VPLs
//!   into the three injection images (one per colour channel) and, with
//!   occlusion, `lpv_geometry.*` the RSM's surfels into the light geometry
//!   volume; then the injection images are copied into the first iteration
//!   buffer and the sum.
//! - `lpv-propagate` (per view): `lpv/propagate.comp`, one dispatch per
//!   iteration, ping-ponging between two buffers and adding into the sum.
//! - `lpv-lookup` (per view): `fullscreen.vert` + `lpv/lookup.frag` write
//!   `indirect` from the sum.
//!
//! Splats are single-texel triangles rasterized into layered 2D-array colour
//! attachments with additive blending (float atomics are not core Vulkan);
//! propagation runs on storage buffers (lavapipe stores to storage images a
//! lane at a time). Barriers are written beside the commands they guard.

use super::Layout;
use crate::frame::{FrameContext, Setup};
use crate::methods::rsm_splat::require_blending;
use crate::methods::IndirectMethod;
use crate::passes::{
    begin_rendering, Attachments, ComputePass, INDIRECT_COMPUTE, INDIRECT_GRAPHICS,
};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, Blend, GraphicsDesc, PassPipeline, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu, Image, ImageDesc};
use anyhow::{bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// The injection images and the SH buffers: RGBA32F (sums of many splats).
pub const SH_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// The geometry volumes: blocking potentials, RGBA32F (copied into a buffer
/// of vec4s as the SH are).
pub const GEOMETRY_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

/// Method `lpv`'s GPU objects for a run; they free themselves when dropped.
pub struct Lpv {
    layout: Layout,
    /// Splat counts: VPLs (and RSM surfels), G-buffer surfels.
    vpls: u32,
    gbuffer_surfels: u32,
    /// Per colour channel: the injected SH, N x N texels, N * C layers.
    injected: [Image; 3],
    /// With occlusion: the blocking potentials from the RSM (per view) and
    /// from the G-buffer (per frame).
    geometry: Option<[Image; 2]>,
    /// Two iterations (ping-pong) and their sum, three SH planes each.
    steps: [Buffer; 2],
    sum: Buffer,
    /// The geometry volumes' copy that propagation reads: two planes (light,
    /// eye); a stand-in of one vec4 without occlusion.
    blocking: Buffer,
    inject: PassPipeline,
    geometry_light: Option<PassPipeline>,
    geometry_eye: Option<PassPipeline>,
    propagate: ComputePass,
    lookup: PassPipeline,
}

impl Lpv {
    pub fn new(setup: &Setup) -> Result<Self> {
        let gpu = setup.gpu;
        let s = setup.settings;
        let layout = Layout::of(s);
        if !gpu.features.shader_output_layer {
            bail!(
                "{} cannot choose the layer in a vertex shader (Vulkan 1.2 shaderOutputLayer), \
                 which method lpv needs to splat into its grids",
                gpu.info.name
            );
        }
        for format in [SH_FORMAT, GEOMETRY_FORMAT] {
            require_blending(gpu, format, "lpv")?;
        }
        let (n, c) = (layout.size, layout.cascades);
        let image = |name: &str, format| {
            Image::new(
                gpu,
                &ImageDesc {
                    name,
                    format,
                    extent: vk::Extent2D {
                        width: n,
                        height: n,
                    },
                    layers: n * c,
                    mips: 1,
                    usage: vk::ImageUsageFlags::COLOR_ATTACHMENT
                        | vk::ImageUsageFlags::SAMPLED
                        | vk::ImageUsageFlags::TRANSFER_SRC,
                },
            )
        };
        let injected = [
            image("lpv injected red", SH_FORMAT)?,
            image("lpv injected green", SH_FORMAT)?,
            image("lpv injected blue", SH_FORMAT)?,
        ];
        let geometry = match layout.occlusion {
            true => Some([
                image("lpv geometry light", GEOMETRY_FORMAT)?,
                image("lpv geometry eye", GEOMETRY_FORMAT)?,
            ]),
            false => None,
        };
        let planes = 3 * layout.cells() * 16;
        let buffer = |name: &str, bytes: u64| {
            Buffer::new(
                gpu,
                name,
                bytes,
                vk::BufferUsageFlags::STORAGE_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_DST
                    | vk::BufferUsageFlags::TRANSFER_SRC,
                MemoryLocation::GpuOnly,
            )
        };
        let steps = [buffer("lpv step a", planes)?, buffer("lpv step b", planes)?];
        let sum = buffer("lpv sum", planes)?;
        let blocking = match layout.occlusion {
            true => buffer("lpv geometry", 2 * layout.cells() * 16)?,
            false => buffer("lpv geometry (unused)", 16)?,
        };

        let (t, samplers) = (setup.targets, setup.samplers);
        let nearest = samplers.nearest;
        let spec = [
            Spec::int("LPV_SIZE", n as i32),
            Spec::int("LPV_CASCADES", c as i32),
            Spec::float("LPV_AHEAD", super::grid::AHEAD),
        ];
        let inject = PassPipeline::graphics(
            gpu,
            setup.frame,
            &[
                Binding::sampled("rsm_position", t.rsm_position.view, nearest),
                Binding::sampled("rsm_normal", t.rsm_normal.view, nearest),
                Binding::sampled("rsm_flux", t.rsm_flux.view, nearest),
            ],
            GraphicsDesc {
                name: "lpv-inject",
                vertex_shader: "lpv/inject.vert",
                fragment_shader: "lpv/inject.frag",
                color_formats: &[SH_FORMAT; 3],
                blend: Blend::Additive,
                specialization: &[
                    spec[0],
                    spec[1],
                    spec[2],
                    Spec::int("LPV_LEVEL", layout.vpl_level as i32),
                ],
                ..Default::default()
            },
        )?;
        let geometry_pass = |from_gbuffer: bool| {
            PassPipeline::graphics(
                gpu,
                setup.frame,
                &[
                    Binding::sampled("rsm_position", t.rsm_position.view, nearest),
                    Binding::sampled("rsm_normal", t.rsm_normal.view, nearest),
                    Binding::sampled("gbuffer_position", t.gbuffer_position.view, nearest),
                    Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, nearest),
                ],
                GraphicsDesc {
                    name: "lpv-geometry",
                    vertex_shader: "lpv/geometry.vert",
                    fragment_shader: "lpv/geometry.frag",
                    color_formats: &[GEOMETRY_FORMAT],
                    blend: Blend::Additive,
                    specialization: &[
                        spec[0],
                        spec[1],
                        spec[2],
                        Spec::bool("FROM_GBUFFER", from_gbuffer),
                        Spec::int("LPV_LEVEL", layout.vpl_level as i32),
                        Spec::int("LPV_STRIDE", layout.gbuffer_stride as i32),
                    ],
                    ..Default::default()
                },
            )
        };
        let (geometry_light, geometry_eye) = match layout.occlusion {
            true => (Some(geometry_pass(false)?), Some(geometry_pass(true)?)),
            false => (None, None),
        };
        let variant = |from: usize| {
            vec![
                Binding::storage("LpvSource", &steps[from]),
                Binding::storage("LpvDestination", &steps[1 - from]),
                Binding::storage("LpvSum", &sum),
                Binding::storage("LpvGeometry", &blocking),
            ]
        };
        let propagate = ComputePass::new(
            setup,
            "lpv-propagate",
            "lpv/propagate.comp",
            &[variant(0), variant(1)],
            0,
            &[
                spec[0],
                spec[1],
                spec[2],
                Spec::bool("OCCLUSION", layout.occlusion),
            ],
        )?;
        let lookup = PassPipeline::graphics(
            gpu,
            setup.frame,
            &[
                Binding::sampled("gbuffer_position", t.gbuffer_position.view, nearest),
                Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, nearest),
                Binding::storage("LpvSum", &sum),
            ],
            GraphicsDesc {
                name: "lpv-lookup",
                vertex_shader: "fullscreen.vert",
                fragment_shader: "lpv/lookup.frag",
                color_formats: &[t.indirect.format],
                specialization: &spec,
                ..Default::default()
            },
        )?;
        let vpl_side = layout.vpl_side(s.rsm_resolution);
        Ok(Self {
            layout,
            vpls: vpl_side * vpl_side,
            gbuffer_surfels: layout.gbuffer_surfels(s.width, s.height),
            injected,
            geometry,
            steps,
            sum,
            blocking,
            inject,
            geometry_light,
            geometry_eye,
            propagate,
            lookup,
        })
    }

    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// The injected SH of the last light view, per colour channel (read-only
    /// between frames).
    pub fn injected(&self) -> &[Image; 3] {
        &self.injected
    }

    /// The geometry volumes (light, eye) of the last view, with occlusion.
    pub fn geometry(&self) -> Option<&[Image; 2]> {
        self.geometry.as_ref()
    }

    /// The propagated sum of the last view: three planes (red, green, blue)
    /// of `Layout::cells` SH vectors (`grid::Grid::from_planes` reads it).
    pub fn sum(&self) -> &Buffer {
        &self.sum
    }

    /// Splats `count` single-texel triangles in each cascade into `targets`
    /// (cleared first), then leaves them as `after`.
    fn splat(
        &self,
        ctx: &FrameContext,
        pipeline: &PassPipeline,
        targets: &[&Image],
        count: u32,
        after: Use,
    ) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        // Discard: the previous view's or frame's readers (propagation,
        // copies) are done first.
        barrier::transition(
            gpu,
            cmd,
            targets,
            Use::DISCARD_AFTER_READERS,
            Use::COLOR_ATTACHMENT,
        );
        let views: Vec<vk::ImageView> = targets.iter().map(|i| i.view).collect();
        let n = self.layout.size;
        begin_rendering(
            gpu,
            cmd,
            &Attachments {
                layers: n * self.layout.cascades,
                ..Attachments::simple(
                    &views,
                    None,
                    vk::Extent2D {
                        width: n,
                        height: n,
                    },
                )
            },
        );
        unsafe {
            pipeline.bind(gpu, cmd, ctx.frame_set);
            gpu.device
                .cmd_draw(cmd, 3 * count, self.layout.cascades, 0, 0);
            gpu.device.cmd_end_rendering(cmd);
        }
        barrier::transition(gpu, cmd, targets, Use::COLOR_ATTACHMENT, after);
    }
}

/// Every access the SH buffers see: propagation's loads and stores, the
/// lookup's loads, the copies in (injection) and out (readback).
const BUFFER_STAGES: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::from_raw(
    vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw()
        | vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw()
        | vk::PipelineStageFlags2::COPY.as_raw(),
);
const BUFFER_WRITES: vk::AccessFlags2 = vk::AccessFlags2::from_raw(
    vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw() | vk::AccessFlags2::TRANSFER_WRITE.as_raw(),
);
const BUFFER_ACCESS: vk::AccessFlags2 = vk::AccessFlags2::from_raw(
    BUFFER_WRITES.as_raw()
        | vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
        | vk::AccessFlags2::TRANSFER_READ.as_raw(),
);

/// Every earlier access to the SH buffers is done, and its writes visible,
/// before any later one.
fn buffers_settled(gpu: &Gpu, cmd: vk::CommandBuffer) {
    barrier::memory(
        gpu,
        cmd,
        BUFFER_STAGES,
        BUFFER_WRITES,
        BUFFER_STAGES,
        BUFFER_ACCESS,
    );
}

/// Copies every layer of `image` (N * C layers of N x N texels: cells in
/// `lpv_cell_index` order) into `buffer` at `offset` bytes.
fn copy_cells(gpu: &Gpu, cmd: vk::CommandBuffer, image: &Image, buffer: &Buffer, offset: u64) {
    let region = vk::BufferImageCopy::default()
        .buffer_offset(offset)
        .image_subresource(vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: image.layers,
        })
        .image_extent(vk::Extent3D {
            width: image.extent.width,
            height: image.extent.height,
            depth: 1,
        });
    unsafe {
        gpu.device.cmd_copy_image_to_buffer(
            cmd,
            image.image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            buffer.buffer,
            &[region],
        );
    }
}

impl IndirectMethod for Lpv {
    fn record_eye_space(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (Some(geometry), Some(pipeline)) = (&self.geometry, &self.geometry_eye) else {
            return;
        };
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        profiler.pass(gpu, cmd, "lpv-geometry", INDIRECT_GRAPHICS, || {
            let eye = &geometry[1];
            self.splat(
                ctx,
                pipeline,
                &[eye],
                self.gbuffer_surfels,
                Use::TRANSFER_SRC,
            );
            // Into the geometry buffer's second plane, once the previous
            // frame's propagation is done with it.
            buffers_settled(gpu, cmd);
            copy_cells(gpu, cmd, eye, &self.blocking, self.layout.cells() * 16);
            barrier::transition(gpu, cmd, &[eye], Use::TRANSFER_SRC, Use::READ_ONLY);
            buffers_settled(gpu, cmd);
        });
    }

    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, _: usize) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let l = self.layout;
        let injected: Vec<&Image> = self.injected.iter().collect();
        profiler.pass(gpu, cmd, "lpv-inject", INDIRECT_GRAPHICS, || {
            self.splat(ctx, &self.inject, &injected, self.vpls, Use::TRANSFER_SRC);
            let light = self.geometry.as_ref().map(|g| &g[0]);
            if let (Some(light), Some(pipeline)) = (light, &self.geometry_light) {
                self.splat(ctx, pipeline, &[light], self.vpls, Use::TRANSFER_SRC);
            }
            // The first iteration and the sum start as the injected SH, each
            // channel's image into its plane of both buffers, and the RSM's
            // blocking into the geometry buffer's first plane, after the
            // previous view's or frame's propagation, lookup and readback
            // are done with them.
            buffers_settled(gpu, cmd);
            let plane = l.cells() * 16;
            for (i, image) in self.injected.iter().enumerate() {
                copy_cells(gpu, cmd, image, &self.steps[0], i as u64 * plane);
                copy_cells(gpu, cmd, image, &self.sum, i as u64 * plane);
            }
            barrier::transition(gpu, cmd, &injected, Use::TRANSFER_SRC, Use::READ_ONLY);
            if let Some(light) = light {
                copy_cells(gpu, cmd, light, &self.blocking, 0);
                barrier::transition(gpu, cmd, &[light], Use::TRANSFER_SRC, Use::READ_ONLY);
            }
            buffers_settled(gpu, cmd);
        });
        profiler.pass(gpu, cmd, "lpv-propagate", INDIRECT_COMPUTE, || {
            // Cells x, then (cascade, z, y) rows: one invocation per cell.
            let extent = vk::Extent2D {
                width: l.size,
                height: l.size * l.size * l.cascades,
            };
            for i in 0..l.iterations {
                if i > 0 {
                    // Iteration i reads i - 1's cells and adds to the sum.
                    barrier::compute_to_compute(gpu, cmd);
                }
                self.propagate.dispatch(ctx, (i % 2) as usize, &[], extent);
            }
            buffers_settled(gpu, cmd);
        });
        let indirect = &ctx.targets.indirect;
        profiler.pass(gpu, cmd, "lpv-lookup", INDIRECT_GRAPHICS, || unsafe {
            barrier::transition(
                gpu,
                cmd,
                &[indirect],
                Use::DISCARD_AFTER_READERS,
                Use::COLOR_ATTACHMENT,
            );
            begin_rendering(
                gpu,
                cmd,
                &Attachments::simple(&[indirect.view], None, indirect.extent),
            );
            self.lookup.bind(gpu, cmd, ctx.frame_set);
            gpu.device.cmd_draw(cmd, 3, 1, 0, 0);
            gpu.device.cmd_end_rendering(cmd);
            barrier::transition(gpu, cmd, &[indirect], Use::COLOR_ATTACHMENT, Use::READ_ONLY);
        });
    }
}
