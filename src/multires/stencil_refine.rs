//! Pass `stencil-refine`: the one-pass stenciled refinement (docs/algorithm.md
//! section 3, step 4). One instanced draw covers every layer of the stencil
//! (`shaders/multires/layered.vert` picks the layer); `shaders/multires/stencil_refine.frag`
//! discards texels that are not patches and the stencil op writes 1 for the
//! rest. Reads `geo_flags`; writes the layered stencil and, in a frame that
//! counts (`Profiler::counting`), the patch counts.

use super::MultiresBuffer;
use crate::frame::{FrameContext, Setup};
use crate::passes::{begin_rendering, Attachments, StencilAttachment, INDIRECT_GRAPHICS};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, GraphicsDesc, PassPipeline, StencilTest};
use crate::vk::profiler::Profiler;
use anyhow::Result;
use ash::vk;

/// The same draw with and without the per-level patch counts (specialisation
/// constant 0 of `multires/stencil_refine.frag`): their atomics are statistics, paid
/// only in the frame that counts, like the profiler's queries.
pub struct StencilRefinePass {
    counting: PassPipeline,
    timed: PassPipeline,
}

impl StencilRefinePass {
    pub fn new(setup: &Setup, m: &MultiresBuffer) -> Result<Self> {
        let t = setup.targets;
        let bindings = [
            Binding::sampled("geo_flags", m.geo_flags.view, setup.samplers.nearest),
            Binding::storage("PatchCounts", &m.patch_counts),
            Binding::sampled(
                "gbuffer_position",
                t.gbuffer_position.view,
                setup.samplers.nearest,
            ),
            Binding::sampled(
                "gbuffer_normal",
                t.gbuffer_normal.view,
                setup.samplers.nearest,
            ),
        ];
        let pipeline = |count: bool| {
            PassPipeline::graphics(
                setup.gpu,
                setup.frame,
                &bindings,
                GraphicsDesc {
                    name: "stencil-refine",
                    vertex_shader: "multires/layered.vert",
                    fragment_shader: "multires/stencil_refine.frag",
                    stencil_format: m.stencil.format,
                    stencil: Some(StencilTest::WRITE_ONE),
                    specialization: &[crate::vk::pipeline::Spec::bool("COUNT", count)],
                    ..Default::default()
                },
            )
        };
        Ok(Self {
            counting: pipeline(true)?,
            timed: pipeline(false)?,
        })
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let d = &gpu.device;
        let counting = profiler.counting();
        profiler.pass(gpu, cmd, "stencil-refine", INDIRECT_GRAPHICS, || unsafe {
            barrier::transition(
                gpu,
                cmd,
                &[&m.stencil],
                Use::DISCARD_AFTER_STENCIL_READERS,
                Use::STENCIL_ATTACHMENT,
            );
            if counting {
                // The previous counting frame's atomics are done before the
                // counts are reset (the host read them after its fence).
                let fragment = vk::PipelineStageFlags2::FRAGMENT_SHADER;
                let rw =
                    vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
                barrier::zero_buffer(
                    gpu,
                    cmd,
                    m.patch_counts.buffer,
                    vk::WHOLE_SIZE,
                    (fragment, vk::AccessFlags2::SHADER_STORAGE_WRITE),
                    (fragment, rw),
                );
            }
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
            match counting {
                true => &self.counting,
                false => &self.timed,
            }
            .bind(gpu, cmd, ctx.frame_set);
            d.cmd_draw(cmd, 6, m.levels + 1, 0, 0);
            d.cmd_end_rendering(cmd);
            barrier::transition(
                gpu,
                cmd,
                &[&m.stencil],
                Use::STENCIL_ATTACHMENT,
                Use::STENCIL_READ_ONLY,
            );
            if counting {
                barrier::memory(
                    gpu,
                    cmd,
                    vk::PipelineStageFlags2::FRAGMENT_SHADER,
                    vk::AccessFlags2::SHADER_STORAGE_WRITE,
                    vk::PipelineStageFlags2::HOST,
                    vk::AccessFlags2::HOST_READ,
                );
            }
        });
    }
}
