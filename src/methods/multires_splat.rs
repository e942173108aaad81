//! Method `multires-splat` (ALGORITHM.md section 5, Nichols & Wyman I3D 2009):
//! every regular VPL splats into every stencilled texel of the
//! multiresolution buffer, additively; then the same upsampling. This is what
//! the paper's stenciled gathering replaced.
//! Pass `splat`: `shaders/multires_splat.vert` + `shaders/multires_splat.frag`,
//! one instanced draw of N x (L + 1) quads, stencil EQUAL 1 before the shader.
//! Reads the geometry mips and the RSM quadtree; writes the illumination
//! buffer and the evaluation counts (barriers: `MultiresBuffer::fill_layers`).

use super::rsm_splat::require_blending;
use crate::multires::MultiresBuffer;
use crate::passes::{FrameContext, INDIRECT_GRAPHICS};
use crate::renderer::FrameInputs;
use crate::vk::pipeline::{Binding, Blend, DescriptorSet, GraphicsDesc, Pipeline, StencilTest};
use crate::vk::profiler::Profiler;
use crate::vk::Gpu;
use anyhow::Result;
use ash::vk;

pub struct MultiresSplatPass {
    pipeline: Pipeline,
    set: DescriptorSet,
    vpls: u32,
}

impl MultiresSplatPass {
    pub fn new(gpu: &Gpu, inputs: &FrameInputs, m: &MultiresBuffer, vpls: u32) -> Result<Self> {
        require_blending(gpu, m.illumination.format, "multires-splat")?;
        require_blending(gpu, m.evaluations.format, "multires-splat")?;
        let (t, s) = (inputs.targets, inputs.samplers);
        let set = DescriptorSet::new(
            gpu,
            "splat",
            &[
                Binding::Uniform(inputs.uniforms),
                Binding::Sampled(m.geo_mean.view, s.nearest),
                Binding::Sampled(m.geo_normal.view, s.nearest),
                Binding::Sampled(t.rsm_position.view, s.nearest),
                Binding::Sampled(t.rsm_normal.view, s.nearest),
                Binding::Sampled(t.rsm_flux.view, s.nearest),
            ],
        )?;
        let pipeline = Pipeline::graphics(
            gpu,
            &GraphicsDesc {
                name: "splat",
                vertex_shader: "multires_splat.vert",
                fragment_shader: "multires_splat.frag",
                set_layouts: &[set.layout],
                color_formats: &[m.illumination.format, m.evaluations.format],
                stencil_format: m.stencil.format,
                stencil: Some(StencilTest::EQUAL_ONE),
                blend: Blend::AdditiveAlphaMax,
                ..Default::default()
            },
        )?;
        Ok(Self {
            pipeline,
            set,
            vpls,
        })
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        profiler.pass(gpu, cmd, "splat", INDIRECT_GRAPHICS, || {
            m.fill_layers(gpu, cmd, true, || unsafe {
                self.pipeline
                    .bind(gpu, cmd, vk::PipelineBindPoint::GRAPHICS, self.set.set);
                gpu.device
                    .cmd_draw(cmd, 6, self.vpls * (m.levels + 1), 0, 0);
            });
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.pipeline.destroy(gpu);
        self.set.destroy(gpu);
    }
}
