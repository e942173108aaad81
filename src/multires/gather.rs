//! Pass `gather`: stenciled gathering into the multiresolution buffer
//! (docs/algorithm.md section 3, step 6). One instanced draw over every layer
//! (`shaders/multires/layered.vert` and the source's fragment shader, which
//! includes `shaders/multires/gather.glsl`), stencil test EQUAL 1 before the
//! shader. Reads the geometry mips, the G-buffer and what the light-space
//! source binds; writes the illumination buffer and the evaluation counts
//! (barriers: `MultiresBuffer::fill_layers`).

use super::{FillPass, LightSource, MultiresBuffer, STENCIL};
use crate::frame::{FrameContext, Setup};
use crate::passes::INDIRECT_GRAPHICS;
use crate::vk::pipeline::{Binding, GraphicsDesc, PassPipeline, StencilTest};
use crate::vk::profiler::Profiler;
use anyhow::Result;
use ash::vk;

/// The first binding of set 1 a source's own bindings take
/// (`GATHER_SOURCE_BINDING` in `shaders/multires/gather.glsl`; the
/// pipeline's binding check holds the two together).
pub const SOURCE_BINDING: usize = 5;

pub struct GatherPass {
    pipeline: PassPipeline,
    stencil: bool,
}

impl GatherPass {
    /// The gather over `m` of the light patches of `source`. With `--stencil
    /// off` the pipeline has no stencil test (measurement baseline).
    pub fn new(setup: &Setup, m: &MultiresBuffer, source: &dyn LightSource) -> Result<Self> {
        let (gpu, t, s) = (setup.gpu, setup.targets, setup.samplers);
        let stencil = STENCIL.get(setup.settings);
        let mut bindings = vec![
            Binding::sampled("geo_mean", m.geo_mean.view, s.nearest),
            Binding::sampled("geo_normal", m.geo_normal.view, s.nearest),
            Binding::sampled("geo_flags", m.geo_flags.view, s.nearest),
            Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
            Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
        ];
        debug_assert_eq!(bindings.len(), SOURCE_BINDING);
        bindings.extend(source.gather_bindings());
        let mut constants = crate::visibility::specialization(setup.settings).to_vec();
        constants.extend(source.gather_constants());
        let pipeline = PassPipeline::graphics(
            gpu,
            setup.frame,
            &bindings,
            GraphicsDesc {
                name: "gather",
                vertex_shader: "multires/layered.vert",
                fragment_shader: source.gather_shader(),
                color_formats: &[m.illumination.format, m.evaluations.format],
                stencil_format: if stencil {
                    m.stencil.format
                } else {
                    vk::Format::UNDEFINED
                },
                stencil: stencil.then_some(StencilTest::EQUAL_ONE),
                specialization: &constants,
                ..Default::default()
            },
        )?;
        Ok(Self { pipeline, stencil })
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
