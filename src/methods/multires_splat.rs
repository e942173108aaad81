//! Method `multires-splat` (docs/algorithm.md section 5, Nichols & Wyman I3D
//! 2009): every regular VPL splats into every stencilled texel of the
//! multiresolution buffer, additively; then the same upsampling. This is what
//! the paper's stenciled gathering replaced.
//! Pass `splat`: `shaders/multires_splat/splat.vert` + `shaders/multires_splat/splat.frag`,
//! one instanced draw of N x (L + 1) quads, stencil EQUAL 1 before the shader.
//! Reads the geometry mips and the RSM quadtree; writes the illumination
//! buffer and the evaluation counts (barriers: `MultiresBuffer::fill_layers`).

use super::rsm_splat::require_blending;
use super::{Descriptor, IndirectMethod};
use crate::frame::{FrameContext, Setup};
use crate::multires::{self, FillPass, MultiresBuffer, MultiresMethod};
use crate::passes::INDIRECT_GRAPHICS;
use crate::regular_vpls::RegularVpls;
use crate::settings::{Method, RenderSettings};
use crate::vk::pipeline::{Binding, Blend, GraphicsDesc, PassPipeline, StencilTest};
use crate::vk::profiler::Profiler;
use anyhow::{bail, Result};

pub const KEY: Method = Method::new("multires-splat");

pub struct MultiresSplatMethod;

impl Descriptor for MultiresSplatMethod {
    fn key(&self) -> Method {
        KEY
    }
    fn color(&self) -> [u8; 3] {
        [255, 127, 14]
    }
    fn help(&self) -> &'static str {
        "Each VPL splats into every patch of the multiresolution buffer."
    }
    fn uses_multires(&self) -> bool {
        true
    }
    fn reads_regular_vpls(&self) -> bool {
        true
    }
    fn reads_visibility(&self) -> bool {
        true
    }
    fn check(&self, s: &RenderSettings) -> Result<()> {
        if !multires::STENCIL.get(s) {
            bail!("--stencil off measures the stenciled gathers; multires-splat always splats through the stencil");
        }
        Ok(())
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        let method = MultiresMethod::filled_by(setup, |setup, m| {
            Ok(Box::new(MultiresSplatPass::new(setup, m)?))
        })?;
        Ok(Box::new(method))
    }
}

pub struct MultiresSplatPass {
    pipeline: PassPipeline,
    vpls: u32,
}

impl MultiresSplatPass {
    pub fn new(setup: &Setup, m: &MultiresBuffer) -> Result<Self> {
        let (gpu, t, s) = (setup.gpu, setup.targets, setup.samplers);
        let vpls = RegularVpls::of(setup.settings);
        require_blending(gpu, m.illumination.format, "multires-splat")?;
        require_blending(gpu, m.evaluations.format, "multires-splat")?;
        let pipeline = PassPipeline::graphics(
            gpu,
            setup.frame,
            &[
                Binding::sampled("geo_mean", m.geo_mean.view, s.nearest),
                Binding::sampled("geo_normal", m.geo_normal.view, s.nearest),
                Binding::sampled("rsm_position", t.rsm_position.view, s.nearest),
                Binding::sampled("rsm_normal", t.rsm_normal.view, s.nearest),
                Binding::sampled("rsm_flux", t.rsm_flux.view, s.nearest),
                Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
                Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
            ],
            GraphicsDesc {
                name: "splat",
                vertex_shader: "multires_splat/splat.vert",
                fragment_shader: "multires_splat/splat.frag",
                color_formats: &[m.illumination.format, m.evaluations.format],
                stencil_format: m.stencil.format,
                stencil: Some(StencilTest::EQUAL_ONE),
                blend: Blend::AdditiveAlphaMax,
                specialization: &[
                    &crate::visibility::specialization(setup.settings)[..],
                    &vpls.specialization(setup.settings),
                ]
                .concat(),
                ..Default::default()
            },
        )?;
        Ok(Self {
            pipeline,
            vpls: vpls.count,
        })
    }
}

impl FillPass for MultiresSplatPass {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        profiler.pass(gpu, cmd, "splat", INDIRECT_GRAPHICS, || {
            m.fill_layers(gpu, cmd, true, || unsafe {
                self.pipeline.bind(gpu, cmd, ctx.frame_set);
                gpu.device
                    .cmd_draw(cmd, 6, self.vpls * (m.levels + 1), 0, 0);
            });
        });
    }
}
