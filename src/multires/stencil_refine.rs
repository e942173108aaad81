//! Pass `stencil-refine`: the one-pass stenciled refinement (ALGORITHM.md
//! section 3, step 4). One instanced draw covers every layer of the stencil
//! (`shaders/layered.vert` picks the layer); `shaders/stencil_refine.frag`
//! discards texels that are not patches and the stencil op writes 1 for the
//! rest. Reads `geo_flags`; writes the layered stencil and the patch counts.

use super::MultiresBuffer;
use crate::passes::{
    begin_rendering, Attachments, FrameContext, StencilAttachment, INDIRECT_GRAPHICS,
};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, DescriptorSet, GraphicsDesc, Pipeline, StencilTest};
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::Result;
use ash::vk;

pub struct StencilRefinePass {
    pipeline: Pipeline,
    set: DescriptorSet,
}

impl StencilRefinePass {
    pub fn new(
        gpu: &Gpu,
        uniforms: &Buffer,
        nearest: vk::Sampler,
        m: &MultiresBuffer,
    ) -> Result<Self> {
        let set = DescriptorSet::new(
            gpu,
            "stencil-refine",
            &[
                Binding::Uniform(uniforms),
                Binding::Sampled(m.geo_flags.view, nearest),
                Binding::Storage(&m.patch_counts),
            ],
        )?;
        let pipeline = Pipeline::graphics(
            gpu,
            &GraphicsDesc {
                name: "stencil-refine",
                vertex_shader: "layered.vert",
                fragment_shader: "stencil_refine.frag",
                set_layouts: &[set.layout],
                stencil_format: m.stencil.format,
                stencil: Some(StencilTest::WRITE_ONE),
                ..Default::default()
            },
        )?;
        Ok(Self { pipeline, set })
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let d = &gpu.device;
        profiler.pass(gpu, cmd, "stencil-refine", INDIRECT_GRAPHICS, || unsafe {
            barrier::transition(
                gpu,
                cmd,
                &[&m.stencil],
                Use::DISCARD_AFTER_STENCIL_READERS,
                Use::STENCIL_ATTACHMENT,
            );
            // The previous frame's atomics are done before the counts are reset
            // (the host read them after that frame's fence).
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::FRAGMENT_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::AccessFlags2::TRANSFER_WRITE,
            );
            d.cmd_fill_buffer(cmd, m.patch_counts.buffer, 0, vk::WHOLE_SIZE, 0);
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::AccessFlags2::TRANSFER_WRITE,
                vk::PipelineStageFlags2::FRAGMENT_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
            );
            begin_rendering(
                gpu,
                cmd,
                &Attachments {
                    extent: m.stencil.extent,
                    layers: m.stencil.layers,
                    colors: &[],
                    clear_colors: true,
                    depth: None,
                    stencil: Some(StencilAttachment {
                        view: m.stencil.view,
                        clear: true,
                    }),
                },
            );
            self.pipeline
                .bind(gpu, cmd, vk::PipelineBindPoint::GRAPHICS, self.set.set);
            d.cmd_draw(cmd, 6, m.levels + 1, 0, 0);
            d.cmd_end_rendering(cmd);
            barrier::transition(
                gpu,
                cmd,
                &[&m.stencil],
                Use::STENCIL_ATTACHMENT,
                Use::STENCIL_READ_ONLY,
            );
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::FRAGMENT_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
                vk::PipelineStageFlags2::HOST,
                vk::AccessFlags2::HOST_READ,
            );
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.pipeline.destroy(gpu);
        self.set.destroy(gpu);
    }
}
