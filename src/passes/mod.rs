//! The passes of one frame that every method shares, one module each, and the
//! pass types they are made of. Every pass records, in one place, its timing
//! scope, its barriers and its draws:
//!
//! 1. [`rsm`]: reflective shadow map from the spot light ([`ScenePass`]).
//! 2. [`gbuffer`]: depth, position, normal, albedo from the camera ([`ScenePass`]).
//! 3. [`shadow`]: the direct light's shadow map, depth only, per light view.
//! 4. [`direct_light`]: direct radiance, PCF on the shadow map ([`FullscreenPass`]).
//! 5. [`rsm_tree`]: the RSM quadtree, for the methods that read it.
//! 6. the method (`methods`): writes `Targets::indirect`.
//! 7. [`composite`]: direct + albedo/pi * indirect irradiance ([`FullscreenPass`]).
//! 8. [`tonemap`]: sRGB display image for the PNG ([`FullscreenPass`]).
//!
//! Barrier convention (see `vk::barrier`): a pass transitions its outputs from
//! "discard, after earlier readers" to attachment use, and at its end leaves
//! them in `SHADER_READ_ONLY_OPTIMAL`, visible to every later reader.
//!
//! Every pipeline's set 0 is the frame set (`frame::FrameSet`); a pass's own
//! inputs are set 1.

pub mod composite;
pub mod direct_light;
pub mod gbuffer;
pub mod light_sum;
pub mod rsm;
pub mod rsm_cube;
pub mod rsm_tree;
pub mod shadow;
pub mod tonemap;

use crate::frame::{FrameContext, SceneGpu, Setup, Targets};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, DescriptorSet, GraphicsDesc, PassPipeline, Pipeline, Spec};
use crate::vk::profiler::{PassKind, Profiler};
use crate::vk::{Gpu, Image};
use anyhow::Result;
use ash::vk;

pub const GRAPHICS: PassKind = PassKind {
    graphics: true,
    indirect: false,
};

/// Timing kind of passes that exist only for indirect light.
pub const INDIRECT_GRAPHICS: PassKind = PassKind {
    graphics: true,
    indirect: true,
};
pub const INDIRECT_COMPUTE: PassKind = PassKind {
    graphics: false,
    indirect: true,
};

/// What a render-pass instance draws into. Colors are cleared to zero, depth
/// to 0 (the far plane of reversed-Z); the stencil is cleared to 0 or kept.
pub struct Attachments<'a> {
    pub extent: vk::Extent2D,
    /// Layers of layered rendering (`gl_Layer`); 1 otherwise.
    pub layers: u32,
    pub colors: &'a [vk::ImageView],
    /// Clear the colors to zero (or keep what they hold).
    pub clear_colors: bool,
    pub depth: Option<vk::ImageView>,
    pub stencil: Option<StencilAttachment>,
}

#[derive(Clone, Copy)]
pub struct StencilAttachment {
    pub view: vk::ImageView,
    /// Clear to 0 (and write), or keep the contents read-only.
    pub clear: bool,
}

impl<'a> Attachments<'a> {
    /// Single-layer color targets plus an optional depth buffer.
    pub fn simple(
        colors: &'a [vk::ImageView],
        depth: Option<vk::ImageView>,
        extent: vk::Extent2D,
    ) -> Self {
        Self {
            extent,
            layers: 1,
            colors,
            clear_colors: true,
            depth,
            stencil: None,
        }
    }

    /// Single-layer color targets that keep what they hold (loaded, not
    /// cleared: the draws write every texel or blend onto it), no depth.
    pub fn loaded(colors: &'a [vk::ImageView], extent: vk::Extent2D) -> Self {
        Self {
            clear_colors: false,
            ..Self::simple(colors, None, extent)
        }
    }
}

/// Starts dynamic rendering into `a` and sets viewport and scissor to its extent.
pub fn begin_rendering(gpu: &Gpu, cmd: vk::CommandBuffer, a: &Attachments) {
    let extent = a.extent;
    let color_attachments: Vec<_> = a
        .colors
        .iter()
        .map(|view| {
            vk::RenderingAttachmentInfo::default()
                .image_view(*view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(if a.clear_colors {
                    vk::AttachmentLoadOp::CLEAR
                } else {
                    vk::AttachmentLoadOp::LOAD
                })
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    color: vk::ClearColorValue { float32: [0.0; 4] },
                })
        })
        .collect();
    let depth_stencil_clear = vk::ClearValue {
        depth_stencil: vk::ClearDepthStencilValue {
            depth: 0.0,
            stencil: 0,
        },
    };
    let depth_attachment = a.depth.map(|view| {
        vk::RenderingAttachmentInfo::default()
            .image_view(view)
            .image_layout(vk::ImageLayout::ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(depth_stencil_clear)
    });
    let stencil_attachment = a.stencil.map(|s| {
        let info = vk::RenderingAttachmentInfo::default().image_view(s.view);
        if s.clear {
            info.image_layout(vk::ImageLayout::ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(depth_stencil_clear)
        } else {
            info.image_layout(vk::ImageLayout::READ_ONLY_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::NONE)
        }
    });
    let area = vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent,
    };
    let mut info = vk::RenderingInfo::default()
        .render_area(area)
        .layer_count(a.layers)
        .color_attachments(&color_attachments);
    if let Some(d) = &depth_attachment {
        info = info.depth_attachment(d);
    }
    if let Some(s) = &stencil_attachment {
        info = info.stencil_attachment(s);
    }
    unsafe {
        gpu.device.cmd_begin_rendering(cmd, &info);
        gpu.device.cmd_set_viewport(
            cmd,
            0,
            &[vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: extent.width as f32,
                height: extent.height as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            }],
        );
        gpu.device.cmd_set_scissor(cmd, 0, &[area]);
    }
}

/// The images a scene pass writes: colors and depth.
pub type SceneOutputs = for<'t> fn(&'t Targets) -> ([&'t Image; 3], &'t Image);

/// A pass that rasterizes the scene's meshes (RSM and G-buffer): color targets
/// plus a reversed-Z depth buffer, one draw per mesh instance, placed by the
/// frame's instance transforms. Set 1 is the scene's (materials, textures).
pub struct ScenePass {
    name: &'static str,
    pipeline: Pipeline,
    outputs: SceneOutputs,
}

impl ScenePass {
    /// `from_light`: rasterize from the light (RSM) rather than the camera.
    pub fn new(
        setup: &Setup,
        name: &'static str,
        fragment_shader: &str,
        from_light: bool,
        outputs: SceneOutputs,
    ) -> Result<Self> {
        let (colors, depth) = outputs(setup.targets);
        let color_formats = colors.map(|c| c.format);
        let pipeline = Pipeline::graphics(
            setup.gpu,
            &GraphicsDesc {
                name,
                vertex_shader: "scene.vert",
                fragment_shader,
                sets: &[setup.frame, &setup.scene.set],
                push_constant_bytes: std::mem::size_of::<crate::gpu_types::DrawPush>() as u32,
                scene_vertices: true,
                color_formats: &color_formats,
                depth_format: depth.format,
                depth_test: Some(vk::CompareOp::GREATER),
                dynamic_cull: true,
                specialization: &[
                    Spec::int("TEXTURE_ARRAYS", setup.scene.texture_arrays_in_use()),
                    Spec::int("VIEW_FROM_LIGHT", from_light as i32),
                ],
                ..Default::default()
            },
        )?;
        Ok(Self {
            name,
            pipeline,
            outputs,
        })
    }

    /// Clears and fills the outputs with the scene, with the barriers of the
    /// convention above on both sides.
    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd, scene) = (ctx.gpu, ctx.cmd, ctx.scene);
        let (colors, depth) = (self.outputs)(ctx.targets);
        profiler.pass(gpu, cmd, self.name, GRAPHICS, || {
            let mut before: Vec<_> = colors
                .iter()
                .map(|c| barrier::image(c, Use::DISCARD_AFTER_READERS, Use::COLOR_ATTACHMENT))
                .collect();
            before.push(barrier::image(
                depth,
                Use::DISCARD_AFTER_READERS,
                Use::DEPTH_ATTACHMENT,
            ));
            barrier::images(gpu, cmd, &before);

            let views = colors.map(|c| c.mip_views[0]);
            begin_rendering(
                gpu,
                cmd,
                &Attachments::simple(&views, Some(depth.view), depth.extent),
            );
            draw_scene(ctx, &self.pipeline, scene, 1);
            unsafe { gpu.device.cmd_end_rendering(cmd) };
            let mut after: Vec<_> = colors
                .iter()
                .map(|c| barrier::image(c, Use::COLOR_ATTACHMENT, Use::READ_ONLY))
                .collect();
            after.push(barrier::image(depth, Use::DEPTH_ATTACHMENT, Use::READ_ONLY));
            barrier::images(gpu, cmd, &after);
        });
    }
}

/// Binds `pipeline` (set 0 the frame set, set 1 the scene's) and draws every
/// mesh instance `instances` times (a layered draw: one instance per layer).
pub fn draw_scene(ctx: &FrameContext, pipeline: &Pipeline, scene: &SceneGpu, instances: u32) {
    draw_scene_with(ctx, pipeline, scene, instances, &[], true);
}

/// [`draw_scene`] with the pass's own sets after the scene's (sets 2..),
/// and single-sided materials culled (`cull`) or drawn from both sides.
pub fn draw_scene_with(
    ctx: &FrameContext,
    pipeline: &Pipeline,
    scene: &SceneGpu,
    instances: u32,
    own: &[vk::DescriptorSet],
    cull: bool,
) {
    let mut sets = vec![ctx.frame_set, scene.set.set];
    sets.extend_from_slice(own);
    draw_scene_sets(ctx, pipeline, scene, instances, &sets, cull);
}

/// [`draw_scene_with`] binding `sets` only (a depth-only pass reads no
/// materials: set 0 alone).
pub fn draw_scene_sets(
    ctx: &FrameContext,
    pipeline: &Pipeline,
    scene: &SceneGpu,
    instances: u32,
    sets: &[vk::DescriptorSet],
    cull: bool,
) {
    let (gpu, cmd) = (ctx.gpu, ctx.cmd);
    let d = &gpu.device;
    unsafe {
        pipeline.bind(gpu, cmd, vk::PipelineBindPoint::GRAPHICS, sets);
        d.cmd_bind_vertex_buffers(cmd, 0, &[scene.vertices.buffer], &[0]);
        d.cmd_bind_index_buffer(cmd, scene.indices.buffer, 0, vk::IndexType::UINT32);
        for draw in &scene.draws {
            let cull = if draw.double_sided || !cull {
                vk::CullModeFlags::NONE
            } else {
                vk::CullModeFlags::BACK
            };
            d.cmd_set_cull_mode(cmd, cull);
            d.cmd_set_front_face(cmd, crate::vk::pipeline::FRONT_FACE);
            d.cmd_push_constants(
                cmd,
                pipeline.layout,
                vk::ShaderStageFlags::ALL_GRAPHICS,
                0,
                bytemuck::bytes_of(&draw.push),
            );
            d.cmd_draw_indexed(
                cmd,
                draw.index_count,
                instances,
                draw.first_index,
                draw.vertex_offset,
                0,
            );
        }
    }
}

/// A pass that runs one fragment shader over every pixel of one output,
/// reading its inputs (set 1) with `texelFetch`: direct light, composite,
/// tonemap and the full-resolution gather.
pub struct FullscreenPass {
    name: &'static str,
    kind: PassKind,
    pipeline: PassPipeline,
    output: fn(&Targets) -> &Image,
}

impl FullscreenPass {
    /// `shader`: the fragment shader and its specialization constants;
    /// `push_constant_bytes` of push constants for `record_with`.
    pub fn new(
        setup: &Setup,
        name: &'static str,
        kind: PassKind,
        (fragment_shader, specialization): (&str, &[Spec]),
        bindings: &[Binding],
        push_constant_bytes: u32,
        output: fn(&Targets) -> &Image,
    ) -> Result<Self> {
        let pipeline = PassPipeline::graphics(
            setup.gpu,
            setup.frame,
            bindings,
            GraphicsDesc {
                name,
                vertex_shader: "fullscreen.vert",
                fragment_shader,
                push_constant_bytes,
                color_formats: &[output(setup.targets).format],
                specialization,
                ..Default::default()
            },
        )?;
        Ok(Self {
            name,
            kind,
            pipeline,
            output,
        })
    }

    /// Writes every pixel of the output, with the convention's barriers.
    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        self.record_with(ctx, profiler, &[]);
    }

    /// As `record`, with push constants.
    pub fn record_with(&self, ctx: &FrameContext, profiler: &mut Profiler, push: &[u8]) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let output = (self.output)(ctx.targets);
        profiler.pass(gpu, cmd, self.name, self.kind, || {
            barrier::transition(
                gpu,
                cmd,
                &[output],
                Use::DISCARD_AFTER_READERS,
                Use::COLOR_ATTACHMENT,
            );
            begin_rendering(
                gpu,
                cmd,
                &Attachments::simple(&[output.view], None, output.extent),
            );
            let d = &gpu.device;
            unsafe {
                self.pipeline.bind(gpu, cmd, ctx.frame_set);
                if !push.is_empty() {
                    d.cmd_push_constants(
                        cmd,
                        self.pipeline.pipeline.layout,
                        vk::ShaderStageFlags::ALL_GRAPHICS,
                        0,
                        push,
                    );
                }
                d.cmd_draw(cmd, 3, 1, 0, 0);
                d.cmd_end_rendering(cmd);
            }
            barrier::transition(gpu, cmd, &[output], Use::COLOR_ATTACHMENT, Use::READ_ONLY);
        });
    }
}

/// A compute shader with one descriptor set (set 1) per dispatch variant (for
/// example one per mip level: storage views of different levels need
/// different sets).
pub struct ComputePass {
    pipeline: Pipeline,
    sets: Vec<DescriptorSet>,
}

impl ComputePass {
    /// `variants[i]` are the bindings of set `i`; all variants share one layout.
    pub fn new(
        setup: &Setup,
        name: &str,
        shader: &str,
        variants: &[Vec<Binding>],
        push_constant_bytes: u32,
        specialization: &[Spec],
    ) -> Result<Self> {
        let sets = variants
            .iter()
            .map(|bindings| DescriptorSet::new(setup.gpu, name, bindings))
            .collect::<Result<Vec<_>>>()?;
        let pipeline = Pipeline::compute(
            setup.gpu,
            name,
            shader,
            &[setup.frame, &sets[0]],
            push_constant_bytes,
            specialization,
        )?;
        Ok(Self { pipeline, sets })
    }

    /// Dispatches 8x8 workgroups covering `extent` with set `variant`.
    pub fn dispatch(&self, ctx: &FrameContext, variant: usize, push: &[u8], extent: vk::Extent2D) {
        let groups = (extent.width.div_ceil(8), extent.height.div_ceil(8));
        self.dispatch_groups(ctx, variant, push, groups);
    }

    /// Dispatches `groups` workgroups (x, y) with set `variant`.
    pub fn dispatch_groups(
        &self,
        ctx: &FrameContext,
        variant: usize,
        push: &[u8],
        groups: (u32, u32),
    ) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let d = &gpu.device;
        self.pipeline.bind(
            gpu,
            cmd,
            vk::PipelineBindPoint::COMPUTE,
            &[ctx.frame_set, self.sets[variant].set],
        );
        unsafe {
            if !push.is_empty() {
                d.cmd_push_constants(
                    cmd,
                    self.pipeline.layout,
                    vk::ShaderStageFlags::COMPUTE,
                    0,
                    push,
                );
            }
            d.cmd_dispatch(cmd, groups.0, groups.1, 1);
        }
    }
}

/// Push-constant bytes of 32-bit values, in order.
pub fn push_bytes(values: &[i32]) -> Vec<u8> {
    bytemuck::cast_slice(values).to_vec()
}
