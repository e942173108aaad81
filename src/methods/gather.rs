//! Pass `gather`: stenciled gathering into the multiresolution buffer
//! (docs/algorithm.md section 3, step 6). One instanced draw over every layer
//! (`shaders/layered.vert` + `shaders/gather.frag`), stencil test EQUAL 1
//! before the shader. Reads the geometry mips and the RSM quadtree (and the
//! ISR list); writes the illumination buffer and the evaluation counts
//! (barriers: `MultiresBuffer::fill_layers`).
//! Which light patches each eye-space patch gathers is the method's choice
//! ([`LightPatches`]); [`MultiresMethod`] puts the passes of every method
//! that works through the multiresolution buffer in order.

use super::IndirectMethod;
use crate::frame::{FrameContext, Setup};
use crate::multires::{Multires, MultiresBuffer};
use crate::passes::INDIRECT_GRAPHICS;
use crate::vk::pipeline::{Binding, GraphicsDesc, PassPipeline, StencilTest};
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::Result;
use ash::vk;

/// The light patches of docs/algorithm.md section 4 (`LIGHT_PATCHES` in the shader).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightPatches {
    /// N regular VPLs: one level of the RSM quadtree.
    Regular = 0,
    /// The list Basic ISR chose this frame.
    ChosenList = 1,
    /// A per-fragment traversal of the quadtree (HISR).
    Traversal = 2,
}

/// What fills the multiresolution buffer's patches: the gather or the splat.
pub trait FillPass {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer);
}

pub struct GatherPass {
    pipeline: PassPipeline,
    stencil: bool,
    /// Bound where there is no chosen list (the descriptor needs a buffer).
    _placeholder: Option<Buffer>,
}

impl GatherPass {
    /// `chosen` is the light-space pass's buffer: Basic ISR's list or HISR's
    /// packed tree (`None` for other sources). With
    /// `--stencil off` the pipeline has no stencil test (measurement baseline).
    pub fn new(
        setup: &Setup,
        m: &MultiresBuffer,
        source: LightPatches,
        chosen: Option<&Buffer>,
    ) -> Result<Self> {
        let (gpu, t, s) = (setup.gpu, setup.targets, setup.samplers);
        let placeholder = match chosen {
            Some(_) => None,
            None => Some(Buffer::new(
                gpu,
                "no chosen patches",
                crate::gpu_types::CHOSEN_PATCHES_HEADER as u64,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                gpu_allocator::MemoryLocation::GpuOnly,
            )?),
        };
        let chosen = chosen.or(placeholder.as_ref()).expect("one of the two");
        let stencil = setup.settings.multires.stencil;
        let pipeline = PassPipeline::graphics(
            gpu,
            setup.frame,
            &[
                Binding::sampled("geo_mean", m.geo_mean.view, s.nearest),
                Binding::sampled("geo_normal", m.geo_normal.view, s.nearest),
                Binding::sampled("geo_flags", m.geo_flags.view, s.nearest),
                Binding::sampled("rsm_position", t.rsm_position.view, s.nearest),
                Binding::sampled("rsm_normal", t.rsm_normal.view, s.nearest),
                Binding::sampled("rsm_flux", t.rsm_flux.view, s.nearest),
                Binding::storage("ChosenPatches", chosen),
            ],
            GraphicsDesc {
                name: "gather",
                vertex_shader: "layered.vert",
                fragment_shader: "gather.frag",
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
            stencil,
            _placeholder: placeholder,
        })
    }
}

impl FillPass for GatherPass {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        profiler.pass(gpu, cmd, "gather", INDIRECT_GRAPHICS, || {
            m.fill_layers(gpu, cmd, self.stencil, || unsafe {
                self.pipeline.bind(gpu, cmd, ctx.frame_set);
                gpu.device.cmd_draw(cmd, 6, m.levels + 1, 0, 0);
            });
        });
    }
}

/// A method's own light-space pass, recorded before the gather: Basic ISR's
/// selection, HISR's tree packing. The gather reads its buffer as
/// `ChosenPatches`.
pub trait LightSpacePass {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler);
    fn buffer(&self) -> &Buffer;
    /// Basic ISR's chosen list (read back for `--stats` and tests).
    fn chosen_list(&self) -> Option<&Buffer> {
        None
    }
    /// HISR's packed light tree (read back by tests).
    fn packed_tree(&self) -> Option<&Buffer> {
        None
    }
}

/// A method that works through the multiresolution buffer: `multires-gather`,
/// `isr`, `hisr` and `multires-splat`. Geometry mips and stencil refinement,
/// the method's own light-space pass, the gather or splat, then upsampling.
pub struct MultiresMethod {
    pub multires: Multires,
    light_pass: Option<Box<dyn LightSpacePass>>,
    fill: Box<dyn FillPass>,
}

impl MultiresMethod {
    /// `fill` makes the pass that fills the buffer's patches, given the
    /// buffer and the light-space pass's buffer (if there is one).
    pub fn new(
        setup: &Setup,
        light_pass: Option<Box<dyn LightSpacePass>>,
        fill: impl FnOnce(&Setup, &MultiresBuffer, Option<&Buffer>) -> Result<Box<dyn FillPass>>,
    ) -> Result<Self> {
        let multires = Multires::new(setup)?;
        let fill = fill(
            setup,
            &multires.buffer,
            light_pass.as_ref().map(|l| l.buffer()),
        )?;
        Ok(Self {
            multires,
            light_pass,
            fill,
        })
    }
}

impl IndirectMethod for MultiresMethod {
    fn record(&self, ctx: &FrameContext, p: &mut Profiler, _: usize) {
        self.multires.record_refinement(ctx, p);
        if let Some(l) = &self.light_pass {
            l.record(ctx, p);
        }
        self.fill.record(ctx, p, &self.multires.buffer);
        self.multires.record_upsample(ctx, p);
    }

    fn multires(&self) -> Option<&MultiresBuffer> {
        Some(&self.multires.buffer)
    }

    fn chosen_patches(&self) -> Option<&Buffer> {
        self.light_pass.as_ref().and_then(|l| l.chosen_list())
    }

    fn packed_light_tree(&self) -> Option<&Buffer> {
        self.light_pass.as_ref().and_then(|l| l.packed_tree())
    }
}
