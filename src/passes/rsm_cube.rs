//! Passes `rsm-cube` and `rsm-face`: a point light's RSM (docs/algorithm.md
//! section 2.4). `rsm-cube` rasterizes the scene once into six-layer RSM
//! images, one layer per cube face (`shaders/rsm_cube.vert` + `rsm_cube.frag`: each
//! scene draw instanced six times, instance f into layer f). Each face is then
//! a light view of its own: `rsm-face` copies its layer into mip 0 of the RSM
//! targets, where the face's `rsm-tree` builds its quadtree and the method
//! walks it exactly as it walks a spot light's RSM. The cube images are made
//! only when the scene has a point light, and are shared by all point lights
//! (views run one after another).
//! Reads the scene; writes the cube images, then the RSM targets' mip 0 and
//! depth (barriers below).

use super::{begin_rendering, draw_scene, Attachments, GRAPHICS};
use crate::frame::targets::{DEPTH_FORMAT, RSM_FORMATS};
use crate::frame::{FrameContext, Setup};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{GraphicsDesc, Pipeline};
use crate::vk::profiler::{PassKind, Profiler};
use crate::vk::{Image, ImageDesc};
use anyhow::{bail, Result};
use ash::vk;

/// Copies: no draws to count fragments of.
const COPY: PassKind = PassKind {
    graphics: false,
    indirect: false,
};

pub struct CubeRsmPass {
    pipeline: Pipeline,
    /// position (xyz, area), normal (xyz, state), flux (rgb, solid angle): six layers each.
    colors: [Image; 3],
    depth: Image,
}

/// Bytes of the cube images at RSM resolution `r`.
pub fn cube_bytes(r: u32) -> u64 {
    let texels = 6 * r as u64 * r as u64;
    texels * (3 * 16 + 4)
}

impl CubeRsmPass {
    pub fn new(setup: &Setup) -> Result<Self> {
        let gpu = setup.gpu;
        if !gpu.features.shader_output_layer {
            bail!(
                "{} cannot write gl_Layer from a vertex shader (Vulkan 1.2 shaderOutputLayer), which the point light's layered cube RSM needs",
                gpu.info.name
            );
        }
        let r = setup.settings.rsm_resolution;
        let extent = vk::Extent2D {
            width: r,
            height: r,
        };
        let desc = |name, format, usage| ImageDesc {
            name,
            format,
            extent,
            layers: 6,
            mips: 1,
            usage,
        };
        let color_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
        let depth_usage =
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
        let colors = [
            Image::new(gpu, &desc("rsm_cube_position", RSM_FORMATS[0], color_usage))?,
            Image::new(gpu, &desc("rsm_cube_normal", RSM_FORMATS[1], color_usage))?,
            Image::new(gpu, &desc("rsm_cube_flux", RSM_FORMATS[2], color_usage))?,
        ];
        let depth = Image::new(gpu, &desc("rsm_cube_depth", DEPTH_FORMAT, depth_usage))?;
        let pipeline = Pipeline::graphics(
            gpu,
            &GraphicsDesc {
                name: "rsm-cube",
                vertex_shader: "rsm_cube.vert",
                fragment_shader: "rsm_cube.frag",
                sets: &[setup.frame, &setup.scene.set],
                push_constant_bytes: std::mem::size_of::<crate::gpu_types::DrawPush>() as u32,
                scene_vertices: true,
                color_formats: &RSM_FORMATS,
                depth_format: DEPTH_FORMAT,
                depth_test: Some(vk::CompareOp::GREATER),
                dynamic_cull: true,
                specialization: &[crate::vk::pipeline::Spec::int(
                    "TEXTURE_ARRAYS",
                    setup.scene.texture_arrays_in_use(),
                )],
                ..Default::default()
            },
        )?;
        Ok(Self {
            pipeline,
            colors,
            depth,
        })
    }

    /// All six faces in one layered draw; leaves the cube images as copy sources.
    pub fn record_cube(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        profiler.pass(gpu, cmd, "rsm-cube", GRAPHICS, || {
            let mut before: Vec<_> = self
                .colors
                .iter()
                .map(|c| barrier::image(c, Use::DISCARD_AFTER_READERS, Use::COLOR_ATTACHMENT))
                .collect();
            before.push(barrier::image(
                &self.depth,
                Use::DISCARD_AFTER_READERS,
                Use::DEPTH_ATTACHMENT,
            ));
            barrier::images(gpu, cmd, &before);
            let views = self.colors.each_ref().map(|c| c.view);
            let attachments = Attachments {
                layers: 6,
                ..Attachments::simple(&views, Some(self.depth.view), self.depth.extent)
            };
            begin_rendering(gpu, cmd, &attachments);
            draw_scene(ctx, &self.pipeline, ctx.scene, 6);
            unsafe { gpu.device.cmd_end_rendering(cmd) };
            let mut after: Vec<_> = self
                .colors
                .iter()
                .map(|c| barrier::image(c, Use::COLOR_ATTACHMENT, Use::TRANSFER_SRC))
                .collect();
            after.push(barrier::image(
                &self.depth,
                Use::DEPTH_ATTACHMENT,
                Use::TRANSFER_SRC,
            ));
            barrier::images(gpu, cmd, &after);
        });
    }

    /// Layer `face` of the cube into the RSM targets' mip 0 and depth, left
    /// readable as the `rsm` pass leaves them.
    pub fn record_face(&self, ctx: &FrameContext, profiler: &mut Profiler, face: u32) {
        let (gpu, cmd, t) = (ctx.gpu, ctx.cmd, ctx.targets);
        let dst = [&t.rsm_position, &t.rsm_normal, &t.rsm_flux];
        profiler.pass(gpu, cmd, "rsm-face", COPY, || {
            // Every mip is discarded, as the `rsm` pass discards them: mip 0
            // receives the face, `rsm-tree` (if the method has it) the rest.
            let mut before: Vec<_> = dst
                .iter()
                .map(|i| barrier::image(i, Use::DISCARD_AFTER_READERS, Use::TRANSFER_DST))
                .collect();
            before.push(barrier::image(
                &t.rsm_depth,
                Use::DISCARD_AFTER_READERS,
                Use::TRANSFER_DST,
            ));
            barrier::images(gpu, cmd, &before);
            let copy = |src: &Image, dst: &Image, aspect| {
                let layer = |base| vk::ImageSubresourceLayers {
                    aspect_mask: aspect,
                    mip_level: 0,
                    base_array_layer: base,
                    layer_count: 1,
                };
                let region = vk::ImageCopy {
                    src_subresource: layer(face),
                    dst_subresource: layer(0),
                    extent: vk::Extent3D {
                        width: src.extent.width,
                        height: src.extent.height,
                        depth: 1,
                    },
                    ..Default::default()
                };
                unsafe {
                    gpu.device.cmd_copy_image(
                        cmd,
                        src.image,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        dst.image,
                        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                        &[region],
                    )
                };
            };
            for (s, d) in self.colors.iter().zip(dst) {
                copy(s, d, vk::ImageAspectFlags::COLOR);
            }
            copy(&self.depth, &t.rsm_depth, vk::ImageAspectFlags::DEPTH);
            let mut after: Vec<_> = dst
                .iter()
                .map(|i| barrier::image(i, Use::TRANSFER_DST, Use::READ_ONLY))
                .collect();
            after.push(barrier::image(
                &t.rsm_depth,
                Use::TRANSFER_DST,
                Use::READ_ONLY,
            ));
            barrier::images(gpu, cmd, &after);
        });
    }
}
