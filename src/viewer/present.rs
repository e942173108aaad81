//! What the viewer adds to the renderer's frame: the `present` pass (the
//! frame's image scaled into the swapchain image, `viewer/present.frag`), the
//! `overlay` pass (text, `viewer/overlay_text.vert/.frag`), an optional copy of the
//! result for a screenshot, and the barriers that hand the swapchain image
//! from acquisition to presentation. Both passes are timed by the frame's
//! profiler like the renderer's own.

use crate::frame::{FrameContext, Targets};
use crate::gpu_types::{OverlayPush, PresentPush};
use crate::passes::{begin_rendering, Attachments, GRAPHICS};
use crate::renderer::FrameExtension;
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, DescriptorSet, GraphicsDesc, Pipeline};
use crate::vk::profiler::Profiler;
use crate::vk::swapchain::{is_srgb, COLOR_RANGE};
use crate::vk::{Buffer, Gpu, Image, ImageDesc, Sampler};
use anyhow::Result;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Text grid of the overlay, in glyphs.
pub const COLUMNS: usize = 60;
pub const ROWS: usize = 28;

/// Letterbox colour around the image (display-encoded).
const LETTERBOX: [f32; 4] = [0.08, 0.08, 0.09, 1.0];

/// The swapchain image's states on its way through a frame.
const ACQUIRED: Use = Use {
    // Chained to the acquire semaphore's wait at this stage.
    stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
    access: vk::AccessFlags2::NONE,
    layout: vk::ImageLayout::UNDEFINED,
};
const PRESENT_SRC: Use = Use {
    // Presentation waits on the frame's semaphore, signalled after all commands.
    stage: vk::PipelineStageFlags2::NONE,
    access: vk::AccessFlags2::NONE,
    layout: vk::ImageLayout::PRESENT_SRC_KHR,
};

fn swapchain_barrier(gpu: &Gpu, cmd: vk::CommandBuffer, image: vk::Image, from: Use, to: Use) {
    let b = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(from.stage)
        .src_access_mask(from.access)
        .dst_stage_mask(to.stage)
        .dst_access_mask(to.access)
        .old_layout(from.layout)
        .new_layout(to.layout)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(COLOR_RANGE)];
    barrier::images(gpu, cmd, &b);
}

/// The glyphs of ASCII 0..127, 8 bytes each (row by row, bit 0 leftmost).
fn font_bytes() -> Vec<u8> {
    font8x8::legacy::BASIC_LEGACY
        .iter()
        .flat_map(|g| g.iter().copied())
        .collect()
}

pub struct Presenter {
    present: Pipeline,
    present_set: DescriptorSet,
    overlay: Pipeline,
    overlay_set: DescriptorSet,
    /// The overlay's cells, rewritten in the command buffer every frame.
    text: Buffer,
    _font: Buffer,
    _sampler: Sampler,
    /// A host-made picture (levels, vpl-count) at render resolution, and its
    /// staging buffer; `upload` is set when the staging holds a new one.
    host_view: Image,
    host_staging: Buffer,
    upload: bool,
    /// The presented image copied back for a screenshot.
    screenshot: Option<Buffer>,
    pub format: vk::Format,
}

impl Presenter {
    pub fn new(
        gpu: &Gpu,
        frame_set: &DescriptorSet,
        targets: &Targets,
        format: vk::Format,
    ) -> Result<Self> {
        let sampler = Sampler::new(
            gpu,
            &vk::SamplerCreateInfo::default()
                .mag_filter(vk::Filter::LINEAR)
                .min_filter(vk::Filter::LINEAR)
                .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .max_lod(0.0),
        )?;
        let extent = targets.display.extent;
        let host_view = Image::new(
            gpu,
            &ImageDesc {
                name: "viewer host view",
                format: vk::Format::R8G8B8A8_UNORM,
                extent,
                layers: 1,
                mips: 1,
                usage: vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
            },
        )?;
        // The present shader binds it in every view, so it starts defined.
        gpu.run_once(|cmd| barrier::clear_color(gpu, cmd, &host_view, Use::READ_ONLY))?;
        let host_staging = Buffer::new(
            gpu,
            "viewer host view (staging)",
            extent.width as u64 * extent.height as u64 * 4,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        let present_set = DescriptorSet::new(
            gpu,
            "present",
            &[
                Binding::sampled("display", targets.display.view, sampler.sampler),
                Binding::sampled("indirect", targets.indirect.view, sampler.sampler),
                Binding::sampled("albedo", targets.gbuffer_albedo.view, sampler.sampler),
                Binding::sampled("host_view", host_view.view, sampler.sampler),
            ],
        )?;
        let present = Pipeline::graphics(
            gpu,
            &GraphicsDesc {
                name: "present",
                vertex_shader: "fullscreen.vert",
                fragment_shader: "viewer/present.frag",
                sets: &[frame_set, &present_set],
                push_constant_bytes: std::mem::size_of::<PresentPush>() as u32,
                color_formats: &[format],
                ..Default::default()
            },
        )?;
        let text = Buffer::new(
            gpu,
            "overlay text",
            (COLUMNS * ROWS * 4) as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let font = Buffer::with_data(
            gpu,
            "overlay font",
            &font_bytes(),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let overlay_set = DescriptorSet::new(
            gpu,
            "overlay",
            &[
                Binding::storage("Text", &text),
                Binding::storage("Font", &font),
            ],
        )?;
        let overlay = Pipeline::graphics(
            gpu,
            &GraphicsDesc {
                name: "overlay",
                vertex_shader: "viewer/overlay_text.vert",
                fragment_shader: "viewer/overlay_text.frag",
                // Set 0 is the frame set in every pipeline, used or not.
                sets: &[frame_set, &overlay_set],
                push_constant_bytes: std::mem::size_of::<OverlayPush>() as u32,
                color_formats: &[format],
                ..Default::default()
            },
        )?;
        Ok(Self {
            present,
            present_set,
            overlay,
            overlay_set,
            text,
            _font: font,
            _sampler: sampler,
            host_view,
            host_staging,
            upload: false,
            screenshot: None,
            format,
        })
    }

    /// Stages an RGBA8 picture at render resolution for `PRESENT_VIEW_HOST`;
    /// call only when no frame is in flight (the staging buffer is reused).
    pub fn stage_host_view(&mut self, rgba: &[u8]) {
        let n = (self.host_staging.size as usize).min(rgba.len());
        self.host_staging.write(0, &rgba[..n]);
        self.upload = true;
    }

    /// The screenshot copied by the last frame that asked for one, as RGBA8;
    /// call after that frame has finished.
    pub fn screenshot_rgba(&self) -> Option<Vec<u8>> {
        let bytes = self.screenshot.as_ref()?.mapped().to_vec();
        let bgra = matches!(
            self.format,
            vk::Format::B8G8R8A8_UNORM | vk::Format::B8G8R8A8_SRGB
        );
        Some(if bgra {
            bytes
                .chunks_exact(4)
                .flat_map(|p| [p[2], p[1], p[0], 255])
                .collect()
        } else {
            bytes
                .chunks_exact(4)
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect()
        })
    }
}

/// One frame's presentation: which swapchain image, what to show on it.
pub struct PresentFrame<'a> {
    pub gpu: &'a Gpu,
    pub presenter: &'a mut Presenter,
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub extent: vk::Extent2D,
    pub acquired: vk::Semaphore,
    pub rendered: vk::Semaphore,
    /// `PRESENT_VIEW_*`.
    pub shown: i32,
    pub cells: &'a [u32],
    /// Copy the presented image for a screenshot.
    pub screenshot: bool,
}

impl PresentFrame<'_> {
    /// Where the render-resolution image lands in the window: as large as
    /// fits, aspect kept, centred.
    fn image_rect(&self, image: vk::Extent2D) -> [i32; 4] {
        let (ww, wh) = (self.extent.width as f64, self.extent.height as f64);
        let s = (ww / image.width as f64).min(wh / image.height as f64);
        let (w, h) = (
            (image.width as f64 * s).round().max(1.0),
            (image.height as f64 * s).round().max(1.0),
        );
        [
            ((ww - w) / 2.0).floor() as i32,
            ((wh - h) / 2.0).floor() as i32,
            w as i32,
            h as i32,
        ]
    }
}

impl FrameExtension for PresentFrame<'_> {
    fn record(&mut self, ctx: &FrameContext, profiler: &mut Profiler) -> Result<()> {
        let (gpu, cmd) = (self.gpu, ctx.cmd);
        let d = &gpu.device;
        let rect = self.image_rect(ctx.targets.display.extent);
        let p = &mut *self.presenter;
        if p.screenshot.as_ref().map(|b| b.size)
            != Some(self.extent.width as u64 * self.extent.height as u64 * 4)
            && self.screenshot
        {
            // No frame in flight reads it: screenshots wait for their frame.
            p.screenshot = Some(Buffer::new(
                gpu,
                "screenshot",
                self.extent.width as u64 * self.extent.height as u64 * 4,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
        }
        let views = [self.view];
        let area = Attachments::simple(&views, None, self.extent);
        profiler.pass(gpu, cmd, "present", GRAPHICS, || unsafe {
            if p.upload {
                p.upload = false;
                let e = p.host_view.extent;
                barrier::transition(
                    gpu,
                    cmd,
                    &[&p.host_view],
                    Use::DISCARD_AFTER_READERS,
                    Use::TRANSFER_DST,
                );
                d.cmd_copy_buffer_to_image(
                    cmd,
                    p.host_staging.buffer,
                    p.host_view.image,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &[vk::BufferImageCopy::default()
                        .image_subresource(vk::ImageSubresourceLayers {
                            aspect_mask: vk::ImageAspectFlags::COLOR,
                            mip_level: 0,
                            base_array_layer: 0,
                            layer_count: 1,
                        })
                        .image_extent(vk::Extent3D {
                            width: e.width,
                            height: e.height,
                            depth: 1,
                        })],
                );
                barrier::transition(gpu, cmd, &[&p.host_view], Use::TRANSFER_DST, Use::READ_ONLY);
            }
            swapchain_barrier(gpu, cmd, self.image, ACQUIRED, Use::COLOR_ATTACHMENT);
            begin_rendering(gpu, cmd, &area);
            p.present.bind(
                gpu,
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                &[ctx.frame_set, p.present_set.set],
            );
            let push = PresentPush {
                rect,
                letterbox: LETTERBOX,
                view: self.shown,
                srgb_target: is_srgb(p.format) as i32,
                ..Default::default()
            };
            d.cmd_push_constants(
                cmd,
                p.present.layout,
                vk::ShaderStageFlags::ALL_GRAPHICS,
                0,
                bytemuck::bytes_of(&push),
            );
            d.cmd_draw(cmd, 3, 1, 0, 0);
            d.cmd_end_rendering(cmd);
        });
        let storage_read = (
            vk::PipelineStageFlags2::FRAGMENT_SHADER,
            vk::AccessFlags2::SHADER_STORAGE_READ,
        );
        let copy_write = (
            vk::PipelineStageFlags2::ALL_TRANSFER,
            vk::AccessFlags2::TRANSFER_WRITE,
        );
        profiler.pass(gpu, cmd, "overlay", GRAPHICS, || unsafe {
            // The previous frame's overlay read the text; this one rewrites it.
            barrier::memory(
                gpu,
                cmd,
                storage_read.0,
                storage_read.1,
                copy_write.0,
                copy_write.1,
            );
            d.cmd_update_buffer(cmd, p.text.buffer, 0, bytemuck::cast_slice(self.cells));
            barrier::memory(
                gpu,
                cmd,
                copy_write.0,
                copy_write.1,
                storage_read.0,
                storage_read.1,
            );
            // The present pass's writes come before the overlay's.
            swapchain_barrier(
                gpu,
                cmd,
                self.image,
                Use::COLOR_ATTACHMENT,
                Use::COLOR_ATTACHMENT,
            );
            let mut load = Attachments::simple(&views, None, self.extent);
            load.clear_colors = false;
            begin_rendering(gpu, cmd, &load);
            p.overlay.bind(
                gpu,
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                &[ctx.frame_set, p.overlay_set.set],
            );
            // Glyphs twice as large on windows wider than 1000 pixels.
            let scale = if self.extent.width > 1000 { 2 } else { 1 };
            let push = OverlayPush {
                rect: [8 * scale, 8 * scale, COLUMNS as i32, ROWS as i32],
                target: [
                    self.extent.width as i32,
                    self.extent.height as i32,
                    scale,
                    0,
                ],
            };
            d.cmd_push_constants(
                cmd,
                p.overlay.layout,
                vk::ShaderStageFlags::ALL_GRAPHICS,
                0,
                bytemuck::bytes_of(&push),
            );
            d.cmd_draw(cmd, 6, 1, 0, 0);
            d.cmd_end_rendering(cmd);
        });
        match (&p.screenshot, self.screenshot) {
            (Some(buffer), true) => unsafe {
                swapchain_barrier(
                    gpu,
                    cmd,
                    self.image,
                    Use::COLOR_ATTACHMENT,
                    Use::TRANSFER_SRC,
                );
                d.cmd_copy_image_to_buffer(
                    cmd,
                    self.image,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    buffer.buffer,
                    &[vk::BufferImageCopy::default()
                        .image_subresource(vk::ImageSubresourceLayers {
                            aspect_mask: vk::ImageAspectFlags::COLOR,
                            mip_level: 0,
                            base_array_layer: 0,
                            layer_count: 1,
                        })
                        .image_extent(vk::Extent3D {
                            width: self.extent.width,
                            height: self.extent.height,
                            depth: 1,
                        })],
                );
                barrier::copies_to_host(gpu, cmd);
                swapchain_barrier(gpu, cmd, self.image, Use::TRANSFER_SRC, PRESENT_SRC);
            },
            _ => swapchain_barrier(gpu, cmd, self.image, Use::COLOR_ATTACHMENT, PRESENT_SRC),
        }
        Ok(())
    }

    fn wait(&self) -> Option<(vk::Semaphore, vk::PipelineStageFlags2)> {
        Some((
            self.acquired,
            vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        ))
    }

    fn signal(&self) -> Option<vk::Semaphore> {
        Some(self.rendered)
    }
}
