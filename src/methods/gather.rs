//! Pass `gather`: stenciled gathering into the multiresolution buffer
//! (docs/algorithm.md section 3, step 6). One instanced draw over every layer
//! (`shaders/multires/layered.vert` + `shaders/multires/gather.frag`), stencil test EQUAL 1
//! before the shader. Reads the geometry mips and the RSM quadtree (and the
//! ISR list); writes the illumination buffer and the evaluation counts
//! (barriers: `MultiresBuffer::fill_layers`).
//! Which light patches each eye-space patch gathers is the method's choice
//! ([`LightPatches`]); `multires_method` puts the passes around it.

use super::multires_method::{FillPass, LightSpacePass};
use crate::frame::{FrameContext, Setup};
use crate::multires::MultiresBuffer;
use crate::passes::INDIRECT_GRAPHICS;
use crate::vk::pipeline::{Binding, GraphicsDesc, PassPipeline, Spec, StencilTest};
use crate::vk::profiler::Profiler;
use anyhow::{anyhow, Result};
use ash::vk;

/// The light patches of docs/algorithm.md section 4 (`LIGHT_PATCHES` in the shader).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightPatches {
    /// A list: the N regular VPLs or the patches Basic ISR chose this frame.
    List = 0,
    /// A per-fragment traversal of the packed quadtree (HISR).
    Traversal = 1,
    /// The same traversal, started from the fragment's tile's cut (HISR with
    /// tiles, `hisr-cut`).
    TiledTraversal = 2,
}

pub struct GatherPass {
    pipeline: PassPipeline,
    stencil: bool,
}

impl GatherPass {
    /// `light` is the light-space pass: its buffer holds the regular VPLs,
    /// Basic ISR's list or HISR's packed tree (and with
    /// `LightPatches::TiledTraversal`, its tile cuts). With `--stencil off`
    /// the pipeline has no stencil test (measurement baseline).
    pub fn new(
        setup: &Setup,
        m: &MultiresBuffer,
        source: LightPatches,
        light: &dyn LightSpacePass,
    ) -> Result<Self> {
        let patches = light.patch_buffer();
        // Bound in every case (the shader declares it); read only when tiled.
        let cuts = match source {
            LightPatches::TiledTraversal => light
                .tile_cuts()
                .ok_or_else(|| anyhow!("a tiled traversal needs the tile cuts"))?,
            _ => patches,
        };
        // HISR's tile-shared visibility and its refinement spread.
        let shared = light
            .shared_visibility_refine()
            .filter(|_| source == LightPatches::TiledTraversal);
        let (gpu, t, s) = (setup.gpu, setup.targets, setup.samplers);
        let stencil = crate::multires::STENCIL.get(setup.settings);
        let visibility = crate::visibility::specialization(setup.settings);
        let pipeline = PassPipeline::graphics(
            gpu,
            setup.frame,
            &[
                Binding::sampled("geo_mean", m.geo_mean.view, s.nearest),
                Binding::sampled("geo_normal", m.geo_normal.view, s.nearest),
                Binding::sampled("geo_flags", m.geo_flags.view, s.nearest),
                Binding::storage("ChosenPatches", patches),
                Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
                Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
                Binding::storage("HisrCut", cuts),
            ],
            GraphicsDesc {
                name: "gather",
                vertex_shader: "multires/layered.vert",
                fragment_shader: "multires/gather.frag",
                color_formats: &[m.illumination.format, m.evaluations.format],
                stencil_format: if stencil {
                    m.stencil.format
                } else {
                    vk::Format::UNDEFINED
                },
                stencil: stencil.then_some(StencilTest::EQUAL_ONE),
                specialization: &[
                    Spec::int("LIGHT_PATCHES", source as i32),
                    Spec::bool("SHARED_VISIBILITY", shared.is_some()),
                    Spec::float("REFINE_SPREAD", shared.unwrap_or(1.0)),
                    visibility[0],
                    visibility[1],
                ],
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
