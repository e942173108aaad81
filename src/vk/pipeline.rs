//! Shader modules from the embedded SPIR-V (`shaders`), and graphics and
//! compute pipelines for dynamic rendering. Descriptor sets live in
//! `descriptors` and are re-exported here, beside the pipelines they feed.

use super::context::Shared;
pub use super::descriptors::{check_bindings, Binding, BindingInfo, DescriptorSet, Resource};
pub use super::specialization::{check_specialization, Spec, SpecValue};
// Re-exported: `tests/layouts.rs` reads the embedded SPIR-V by this path.
pub use super::shaders::{shader_names, spirv};
use super::Gpu;
use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;
use std::sync::Arc;

fn shader_module(gpu: &Gpu, name: &str) -> Result<vk::ShaderModule> {
    let code = spirv(name)?;
    let module = unsafe {
        gpu.device
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&code), None)
    }
    .with_context(|| format!("creating shader module {name}"))?;
    gpu.name(module, name);
    Ok(module)
}

thread_local! {
    /// Test hook: pipelines this thread may still create before one fails.
    static PIPELINES_BEFORE_FAILURE: std::cell::Cell<Option<u32>> = const { std::cell::Cell::new(None) };
    /// Test hook: pipelines this thread has gone on to create (see
    /// [`pipelines_created`]).
    static PIPELINES_CREATED: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Makes the pipeline creation after the next `n` on this thread fail, so a
/// test can show that setup failing half-way frees what it had made. `None`
/// switches the failure off.
#[doc(hidden)]
pub fn fail_pipeline_creation_after(n: Option<u32>) {
    PIPELINES_BEFORE_FAILURE.with(|c| c.set(n));
}

/// How many pipelines this thread has gone on to create so far: every one
/// [`fail_pipeline_creation_after`] counts and did not fail. A test takes the
/// difference over a setup that succeeded to know how many pipelines it
/// makes, so that it can make each of them fail in turn.
#[doc(hidden)]
pub fn pipelines_created() -> u64 {
    PIPELINES_CREATED.with(|c| c.get())
}

fn injected_failure(name: &str) -> Result<()> {
    PIPELINES_BEFORE_FAILURE.with(|c| match c.get() {
        Some(0) => {
            c.set(None);
            bail!("creating pipeline {name}: failure injected by a test")
        }
        Some(n) => {
            c.set(Some(n - 1));
            Ok(())
        }
        None => Ok(()),
    })?;
    PIPELINES_CREATED.with(|c| c.set(c.get() + 1));
    Ok(())
}

/// glTF front faces are counter-clockwise seen from the front. Vulkan's
/// orientation is the one seen in the framebuffer, and the projections flip y
/// so images stay upright, so the winding the camera sees is kept.
pub const FRONT_FACE: vk::FrontFace = vk::FrontFace::COUNTER_CLOCKWISE;

/// How a graphics pipeline rasterizes and what it writes.
pub struct GraphicsDesc<'a> {
    pub name: &'a str,
    pub vertex_shader: &'a str,
    pub fragment_shader: &'a str,
    /// Set i of the pipeline layout (checked against the shaders' bindings).
    pub sets: &'a [&'a DescriptorSet],
    pub push_constant_bytes: u32,
    /// Scene vertex input (`scene::GpuVertex`); `false` for full-screen triangles.
    pub scene_vertices: bool,
    pub color_formats: &'a [vk::Format],
    pub depth_format: vk::Format,
    /// Depth test with this compare op and depth writes; `None` disables both.
    pub depth_test: Option<vk::CompareOp>,
    /// A stencil attachment of this format with this test (`UNDEFINED`: none).
    pub stencil_format: vk::Format,
    pub stencil: Option<StencilTest>,
    /// Blending on every color attachment.
    pub blend: Blend,
    /// Cull mode is set per draw (glTF `doubleSided`), so it is dynamic state.
    pub dynamic_cull: bool,
    /// The shaders' specialization constants, by name (every one they
    /// declare, checked against their SPIR-V).
    pub specialization: &'a [Spec],
}

impl Default for GraphicsDesc<'_> {
    fn default() -> Self {
        Self {
            name: "",
            vertex_shader: "fullscreen.vert",
            fragment_shader: "",
            sets: &[],
            push_constant_bytes: 0,
            scene_vertices: false,
            color_formats: &[],
            depth_format: vk::Format::UNDEFINED,
            depth_test: None,
            stencil_format: vk::Format::UNDEFINED,
            stencil: None,
            blend: Blend::None,
            dynamic_cull: false,
            specialization: &[],
        }
    }
}

/// How fragments combine with what the attachment holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Overwrite.
    None,
    /// `dst + src` in every channel (splatting).
    Additive,
    /// `dst + src` in color, `max(dst, src)` in alpha (splatting a flag).
    AdditiveAlphaMax,
}

/// Stencil state for front and back faces alike; the reference is 1.
#[derive(Clone, Copy, Debug)]
pub struct StencilTest {
    pub compare: vk::CompareOp,
    /// Operation when the stencil (and depth) test passes; `KEEP` for read-only.
    pub pass_op: vk::StencilOp,
}

impl StencilTest {
    /// Texels where stencil == 1, read-only.
    pub const EQUAL_ONE: StencilTest = StencilTest {
        compare: vk::CompareOp::EQUAL,
        pass_op: vk::StencilOp::KEEP,
    };
    /// Writes 1 wherever the fragment survives (is not discarded).
    pub const WRITE_ONE: StencilTest = StencilTest {
        compare: vk::CompareOp::ALWAYS,
        pass_op: vk::StencilOp::REPLACE,
    };
}

/// A pipeline and its layout, destroyed when dropped.
pub struct Pipeline {
    pub pipeline: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    shared: Arc<Shared>,
}

impl Pipeline {
    /// Checks the shaders' bindings against `sets` and makes the layout; the
    /// returned value (null pipeline) frees the layout if a later step fails.
    fn with_layout(
        gpu: &Gpu,
        name: &str,
        shaders: &[&str],
        sets: &[&DescriptorSet],
        push: vk::PushConstantRange,
    ) -> Result<Self> {
        let infos: Vec<&[BindingInfo]> = sets.iter().map(|s| s.bindings.as_slice()).collect();
        check_bindings(name, shaders, &infos)?;
        injected_failure(name)?;
        let layouts: Vec<_> = sets.iter().map(|s| s.layout).collect();
        let ranges = [push];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts);
        if push.size > 0 {
            layout_info = layout_info.push_constant_ranges(&ranges);
        }
        let layout = unsafe { gpu.device.create_pipeline_layout(&layout_info, None) }?;
        Ok(Self {
            pipeline: vk::Pipeline::null(),
            layout,
            shared: gpu.shared.clone(),
        })
    }

    pub fn graphics(gpu: &Gpu, desc: &GraphicsDesc) -> Result<Self> {
        let mut out = Self::with_layout(
            gpu,
            desc.name,
            &[desc.vertex_shader, desc.fragment_shader],
            desc.sets,
            vk::PushConstantRange {
                stage_flags: vk::ShaderStageFlags::ALL_GRAPHICS,
                offset: 0,
                size: desc.push_constant_bytes,
            },
        )?;
        let layout = out.layout;
        let constants = super::specialization::resolve(
            desc.name,
            &[desc.vertex_shader, desc.fragment_shader],
            desc.specialization,
        )?;
        let vs = shader_module(gpu, desc.vertex_shader)?;
        let fs = match shader_module(gpu, desc.fragment_shader) {
            Ok(fs) => fs,
            Err(e) => {
                unsafe { gpu.device.destroy_shader_module(vs, None) };
                return Err(e);
            }
        };
        let spec: Vec<vk::SpecializationInfo> = constants
            .iter()
            .map(|c| {
                vk::SpecializationInfo::default()
                    .map_entries(&c.entries)
                    .data(&c.data)
            })
            .collect();
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vs)
                .name(c"main")
                .specialization_info(&spec[0]),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fs)
                .name(c"main")
                .specialization_info(&spec[1]),
        ];

        let vertex_bindings = [vk::VertexInputBindingDescription {
            binding: 0,
            stride: std::mem::size_of::<crate::scene::GpuVertex>() as u32,
            input_rate: vk::VertexInputRate::VERTEX,
        }];
        let vertex_attributes = crate::scene::GpuVertex::attributes();
        let mut vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        if desc.scene_vertices {
            vertex_input = vertex_input
                .vertex_binding_descriptions(&vertex_bindings)
                .vertex_attribute_descriptions(&vertex_attributes);
        }
        let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .front_face(FRONT_FACE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let stencil_op = desc.stencil.map(|t| {
            vk::StencilOpState::default()
                .fail_op(vk::StencilOp::KEEP)
                .depth_fail_op(vk::StencilOp::KEEP)
                .pass_op(t.pass_op)
                .compare_op(t.compare)
                .compare_mask(0xff)
                .write_mask(0xff)
                .reference(1)
        });
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth_test.is_some())
            .depth_write_enable(desc.depth_test.is_some())
            .depth_compare_op(desc.depth_test.unwrap_or(vk::CompareOp::ALWAYS))
            .stencil_test_enable(stencil_op.is_some())
            .front(stencil_op.unwrap_or_default())
            .back(stencil_op.unwrap_or_default());
        let blend_attachments: Vec<_> = desc
            .color_formats
            .iter()
            .map(|_| {
                let b = vk::PipelineColorBlendAttachmentState::default()
                    .color_write_mask(vk::ColorComponentFlags::RGBA);
                let alpha_op = match desc.blend {
                    Blend::None => return b,
                    Blend::Additive => vk::BlendOp::ADD,
                    Blend::AdditiveAlphaMax => vk::BlendOp::MAX,
                };
                b.blend_enable(true)
                    .src_color_blend_factor(vk::BlendFactor::ONE)
                    .dst_color_blend_factor(vk::BlendFactor::ONE)
                    .color_blend_op(vk::BlendOp::ADD)
                    .src_alpha_blend_factor(vk::BlendFactor::ONE)
                    .dst_alpha_blend_factor(vk::BlendFactor::ONE)
                    .alpha_blend_op(alpha_op)
            })
            .collect();
        let blend =
            vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let mut dynamic_states = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        if desc.dynamic_cull {
            // Front face is dynamic too: lavapipe (Mesa 22.3) ignores the static
            // front face once cull mode is dynamic.
            dynamic_states.extend([vk::DynamicState::CULL_MODE, vk::DynamicState::FRONT_FACE]);
        }
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(desc.color_formats)
            .depth_attachment_format(desc.depth_format)
            .stencil_attachment_format(desc.stencil_format);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&input_assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout)
            .push_next(&mut rendering);
        let result = unsafe {
            gpu.device
                .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
        };
        unsafe {
            gpu.device.destroy_shader_module(vs, None);
            gpu.device.destroy_shader_module(fs, None);
        }
        out.pipeline = result.map_err(|(_, e)| anyhow!("creating pipeline {}: {e}", desc.name))?[0];
        gpu.name(out.pipeline, desc.name);
        Ok(out)
    }

    /// A compute pipeline running `shader` (entry `main`).
    pub fn compute(
        gpu: &Gpu,
        name: &str,
        shader: &str,
        sets: &[&DescriptorSet],
        push_constant_bytes: u32,
        specialization: &[Spec],
    ) -> Result<Self> {
        let mut out = Self::with_layout(
            gpu,
            name,
            &[shader],
            sets,
            vk::PushConstantRange {
                stage_flags: vk::ShaderStageFlags::COMPUTE,
                offset: 0,
                size: push_constant_bytes,
            },
        )?;
        let layout = out.layout;
        let constants = super::specialization::resolve(name, &[shader], specialization)?;
        let module = shader_module(gpu, shader)?;
        let spec = vk::SpecializationInfo::default()
            .map_entries(&constants[0].entries)
            .data(&constants[0].data);
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec);
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout);
        let result = unsafe {
            gpu.device
                .create_compute_pipelines(vk::PipelineCache::null(), &[info], None)
        };
        unsafe { gpu.device.destroy_shader_module(module, None) };
        out.pipeline = result.map_err(|(_, e)| anyhow!("creating pipeline {name}: {e}"))?[0];
        gpu.name(out.pipeline, name);
        Ok(out)
    }

    /// Binds the pipeline with `sets` (set 0 first) for graphics or compute.
    pub fn bind(
        &self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        point: vk::PipelineBindPoint,
        sets: &[vk::DescriptorSet],
    ) {
        unsafe {
            gpu.device.cmd_bind_pipeline(cmd, point, self.pipeline);
            gpu.device
                .cmd_bind_descriptor_sets(cmd, point, self.layout, 0, sets, &[]);
        }
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        unsafe {
            self.shared.device.destroy_pipeline(self.pipeline, None);
            self.shared
                .device
                .destroy_pipeline_layout(self.layout, None);
        }
    }
}

/// A graphics pipeline with the one descriptor set of its own (set 1) that
/// many passes pair it with; set 0 is the frame set.
pub struct PassPipeline {
    pub pipeline: Pipeline,
    pub set: DescriptorSet,
}

impl PassPipeline {
    /// `desc.sets` is filled in: [`frame`, the set made from `bindings`].
    pub fn graphics(
        gpu: &Gpu,
        frame: &DescriptorSet,
        bindings: &[Binding],
        desc: GraphicsDesc,
    ) -> Result<Self> {
        let set = DescriptorSet::new(gpu, desc.name, bindings)?;
        let pipeline = Pipeline::graphics(
            gpu,
            &GraphicsDesc {
                sets: &[frame, &set],
                ..desc
            },
        )?;
        Ok(Self { pipeline, set })
    }

    /// Binds the pipeline, `frame_set` as set 0 and its own set as set 1.
    pub fn bind(&self, gpu: &Gpu, cmd: vk::CommandBuffer, frame_set: vk::DescriptorSet) {
        self.pipeline.bind(
            gpu,
            cmd,
            vk::PipelineBindPoint::GRAPHICS,
            &[frame_set, self.set.set],
        );
    }
}
