//! Pass `gather`: stenciled gathering into the multiresolution buffer
//! (ALGORITHM.md section 3 step 6). One instanced draw over every layer
//! (`shaders/layered.vert` + `shaders/gather.frag`), stencil test EQUAL 1
//! before the shader. Reads the geometry mips and the RSM quadtree (and the
//! ISR list); writes the illumination buffer and the evaluation counts
//! (barriers: `MultiresBuffer::fill_layers`).
//! Which light patches each eye-space patch gathers is the method's choice
//! ([`LightPatches`]); [`GatherMethod`] puts the method's passes in order.

use super::isr::IsrSelectPass;
use super::multires_splat::MultiresSplatPass;
use crate::multires::{Multires, MultiresBuffer};
use crate::passes::{FrameContext, INDIRECT_GRAPHICS};
use crate::renderer::{isr_base_mip, levels_of, FrameInputs, Method, RenderSettings};
use crate::vk::pipeline::{Binding, DescriptorSet, GraphicsDesc, Pipeline, StencilTest};
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::Result;
use ash::vk;

/// The light patches of ALGORITHM.md section 4 (`LIGHT_PATCHES` in the shader).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightPatches {
    /// N regular VPLs: one level of the RSM quadtree.
    Regular = 0,
    /// The list Basic ISR chose this frame.
    ChosenList = 1,
    /// A per-fragment traversal of the quadtree (HISR).
    Traversal = 2,
}

pub struct GatherPass {
    pipeline: Pipeline,
    set: DescriptorSet,
    stencil: bool,
}

impl GatherPass {
    /// With `stencil` false the pipeline has no stencil test (measurement
    /// baseline). `chosen` is Basic ISR's list (any buffer for other sources).
    pub fn new(
        gpu: &Gpu,
        inputs: &FrameInputs,
        m: &MultiresBuffer,
        source: LightPatches,
        chosen: &Buffer,
        stencil: bool,
    ) -> Result<Self> {
        let (uniforms, t, s) = (inputs.uniforms, inputs.targets, inputs.samplers);
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
                Binding::Storage(chosen),
            ],
        )?;
        let pipeline = Pipeline::graphics(
            gpu,
            &GraphicsDesc {
                name: "gather",
                vertex_shader: "layered.vert",
                fragment_shader: "gather.frag",
                set_layouts: &[set.layout],
                color_formats: &[m.illumination.format, m.evaluations.format],
                stencil_format: if stencil {
                    m.stencil.format
                } else {
                    vk::Format::UNDEFINED
                },
                stencil: stencil.then_some(StencilTest::EQUAL_ONE),
                specialization: &[(0, source as i32)],
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
        profiler.pass(gpu, cmd, "gather", INDIRECT_GRAPHICS, || {
            m.fill_layers(gpu, cmd, self.stencil, || unsafe {
                self.pipeline
                    .bind(gpu, cmd, vk::PipelineBindPoint::GRAPHICS, self.set.set);
                gpu.device.cmd_draw(cmd, 6, m.levels + 1, 0, 0);
            });
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.pipeline.destroy(gpu);
        self.set.destroy(gpu);
    }
}

/// What fills the multiresolution buffer's patches.
enum Fill {
    Gather(GatherPass),
    Splat(MultiresSplatPass),
}

/// A method that works through the multiresolution buffer: `multires-gather`,
/// `isr`, `hisr` and `multires-splat`. Geometry mips and stencil refinement,
/// the method's own light-space passes, the gather (or splat), then upsampling.
pub struct GatherMethod {
    pub multires: Multires,
    /// Basic ISR's patch selection (method `isr` only).
    pub isr: Option<IsrSelectPass>,
    fill: Fill,
    /// Bound for methods without a chosen list (the descriptor needs a buffer).
    placeholder: Option<Buffer>,
}

impl GatherMethod {
    pub fn new(gpu: &Gpu, inputs: &FrameInputs, settings: &RenderSettings) -> Result<Self> {
        let (uniforms, t, s) = (inputs.uniforms, inputs.targets, inputs.samplers);
        let multires = Multires::new(gpu, uniforms, t, s, levels_of(settings))?;
        let method = settings.method;
        let (source, isr) = match method {
            Method::Isr => (
                LightPatches::ChosenList,
                Some(IsrSelectPass::new(
                    gpu,
                    uniforms,
                    t,
                    s,
                    isr_base_mip(settings),
                )?),
            ),
            Method::Hisr => (LightPatches::Traversal, None),
            _ => (LightPatches::Regular, None),
        };
        let placeholder = match &isr {
            Some(_) => None,
            None => Some(Buffer::new(
                gpu,
                "no chosen patches",
                crate::gpu_types::CHOSEN_PATCHES_HEADER as u64,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                gpu_allocator::MemoryLocation::GpuOnly,
            )?),
        };
        let chosen = isr
            .as_ref()
            .map(|i| &i.chosen)
            .or(placeholder.as_ref())
            .unwrap();
        let fill = if method == Method::MultiresSplat {
            Fill::Splat(MultiresSplatPass::new(
                gpu,
                inputs,
                &multires.buffer,
                settings.vpls,
            )?)
        } else {
            let stencil = settings.multires.stencil;
            Fill::Gather(GatherPass::new(
                gpu,
                inputs,
                &multires.buffer,
                source,
                chosen,
                stencil,
            )?)
        };
        Ok(Self {
            multires,
            isr,
            fill,
            placeholder,
        })
    }

    pub fn record(&self, ctx: &FrameContext, p: &mut Profiler) {
        self.multires.record_refinement(ctx, p);
        if let Some(isr) = &self.isr {
            isr.record(ctx, p);
        }
        match &self.fill {
            Fill::Gather(g) => g.record(ctx, p, &self.multires.buffer),
            Fill::Splat(s) => s.record(ctx, p, &self.multires.buffer),
        }
        self.multires.record_upsample(ctx, p);
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        match &mut self.fill {
            Fill::Gather(g) => g.destroy(gpu),
            Fill::Splat(s) => s.destroy(gpu),
        }
        if let Some(i) = &mut self.isr {
            i.destroy(gpu);
        }
        if let Some(b) = &mut self.placeholder {
            b.destroy(gpu);
        }
        self.multires.destroy(gpu);
    }
}
