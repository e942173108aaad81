//! Method `multires-gather`: stenciled gathering from N regular VPLs
//! (ALGORITHM.md section 3 step 6, and section 4 "Regular N VPLs").
//! Pass `gather`: one instanced draw over every layer of the illumination
//! buffer (`shaders/layered.vert` + `shaders/multires_gather.frag`), stencil
//! test EQUAL 1 before the shader. Reads the geometry mips and the RSM
//! quadtree; writes the illumination buffer. The hierarchy's other passes are
//! in `multires::Multires`.

use crate::multires::{Multires, MultiresBuffer};
use crate::passes::{
    begin_rendering, Attachments, FrameContext, StencilAttachment, INDIRECT_GRAPHICS,
};
use crate::renderer::{Samplers, Targets};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, DescriptorSet, GraphicsDesc, Pipeline, StencilTest};
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::Result;
use ash::vk;

pub struct GatherPass {
    pipeline: Pipeline,
    set: DescriptorSet,
    stencil: bool,
}

impl GatherPass {
    /// With `stencil` false the pipeline has no stencil test (measurement baseline).
    pub fn new(
        gpu: &Gpu,
        uniforms: &Buffer,
        t: &Targets,
        s: &Samplers,
        m: &MultiresBuffer,
        stencil: bool,
    ) -> Result<Self> {
        let set = DescriptorSet::new(
            gpu,
            "gather",
            &[
                Binding::Uniform(uniforms),
                Binding::Sampled(m.geo_mean.view, s.nearest),
                Binding::Sampled(m.geo_normal.view, s.nearest),
                Binding::Sampled(m.geo_flags.view, s.nearest),
                Binding::Sampled(t.rsm_position.view, s.nearest),
                Binding::Sampled(t.rsm_normal.view, s.nearest),
                Binding::Sampled(t.rsm_flux.view, s.nearest),
            ],
        )?;
        let pipeline = Pipeline::graphics(
            gpu,
            &GraphicsDesc {
                name: "gather",
                vertex_shader: "layered.vert",
                fragment_shader: "multires_gather.frag",
                set_layouts: &[set.layout],
                color_formats: &[m.illumination.format],
                stencil_format: if stencil {
                    m.stencil.format
                } else {
                    vk::Format::UNDEFINED
                },
                stencil: stencil.then_some(StencilTest::EQUAL_ONE),
                ..Default::default()
            },
        )?;
        Ok(Self {
            pipeline,
            set,
            stencil,
        })
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let d = &gpu.device;
        profiler.pass(gpu, cmd, "gather", INDIRECT_GRAPHICS, || unsafe {
            barrier::transition(
                gpu,
                cmd,
                &[&m.illumination],
                Use::DISCARD_AFTER_READERS,
                Use::COLOR_ATTACHMENT,
            );
            let colors = [m.illumination.view];
            begin_rendering(
                gpu,
                cmd,
                &Attachments {
                    extent: m.illumination.extent,
                    layers: m.illumination.layers,
                    colors: &colors,
                    depth: None,
                    stencil: self.stencil.then_some(StencilAttachment {
                        view: m.stencil.view,
                        clear: false,
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
                &[&m.illumination],
                Use::COLOR_ATTACHMENT,
                Use::READ_ONLY,
            );
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.pipeline.destroy(gpu);
        self.set.destroy(gpu);
    }
}

/// The whole method: the hierarchy plus the gather.
pub struct MultiresGather {
    pub multires: Multires,
    gather: GatherPass,
}

impl MultiresGather {
    pub fn new(
        gpu: &Gpu,
        uniforms: &Buffer,
        t: &Targets,
        s: &Samplers,
        levels: u32,
        stencil: bool,
    ) -> Result<Self> {
        let multires = Multires::new(gpu, uniforms, t, s, levels)?;
        let gather = GatherPass::new(gpu, uniforms, t, s, &multires.buffer, stencil)?;
        Ok(Self { multires, gather })
    }

    pub fn record(&self, ctx: &FrameContext, p: &mut Profiler) {
        self.multires.record_refinement(ctx, p);
        self.gather.record(ctx, p, &self.multires.buffer);
        self.multires.record_upsample(ctx, p);
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.gather.destroy(gpu);
        self.multires.destroy(gpu);
    }
}
