//! Pass `geometry-mips`: levels 1..=L of the geometry mipmaps (docs/algorithm.md
//! section 3, steps 2-4) with `shaders/geometry_mips.comp`, one dispatch per
//! level (level 0 is the G-buffer itself). Reads the G-buffer; writes `geo_*`
//! (barriers below).

use super::MultiresBuffer;
use crate::frame::{FrameContext, Setup};
use crate::passes::{ComputePass, INDIRECT_COMPUTE};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use anyhow::Result;

/// Level 1 and the levels above are separate pipelines (`geometry_mips.comp`'s
/// specialisation constant LEVEL_ONE): CPU drivers execute every branch under
/// a lane mask, so one pipeline would run the reads of both for every texel.
pub struct GeometryMipsPass {
    level_one: ComputePass,
    /// Levels 2..=L, one descriptor set each (none with L = 1).
    above: Option<ComputePass>,
}

const LEVEL_ONE: u32 = 0;

/// Shader names of the five chains' source (`src_*`) and destination (`dst_*`)
/// bindings, in `MultiresBuffer::geometry_images` order.
const SOURCES: [&str; 5] = ["src_mean", "src_normal", "src_min", "src_max", "src_flags"];
const DESTINATIONS: [&str; 5] = ["dst_mean", "dst_normal", "dst_min", "dst_max", "dst_flags"];

impl GeometryMipsPass {
    pub fn new(setup: &Setup, m: &MultiresBuffer) -> Result<Self> {
        let (t, s) = (setup.targets, setup.samplers);
        let images = m.geometry_images();
        let levels = m.levels as usize;
        // Every chain holds levels 1..=L (mip m is level m + 1; level 0 is
        // the G-buffer). Level 1 reads the G-buffer, so its source bindings
        // are unused and point at a mip it does not write (the last one).
        let mip_of = |level: usize| level.checked_sub(1).unwrap_or(levels - 1);
        let bindings = |l: usize| {
            let mut b = vec![
                Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
                Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
            ];
            for (names, level) in [(SOURCES, l - 1), (DESTINATIONS, l)] {
                b.extend(
                    images
                        .iter()
                        .zip(names)
                        .map(|(i, name)| Binding::storage_image(name, i.mip_views[mip_of(level)])),
                );
            }
            b
        };
        let pass = |level_one: bool, variants: Vec<Vec<Binding>>| {
            ComputePass::new(
                setup,
                "geometry-mips",
                "geometry_mips.comp",
                &variants,
                0,
                &[(LEVEL_ONE, level_one as i32)],
            )
        };
        Ok(Self {
            level_one: pass(true, vec![bindings(1)])?,
            above: match levels {
                1 => None,
                _ => Some(pass(false, (2..=levels).map(bindings).collect())?),
            },
        })
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let images = m.geometry_images();
        profiler.pass(gpu, cmd, "geometry-mips", INDIRECT_COMPUTE, || {
            barrier::transition(
                gpu,
                cmd,
                &images,
                Use::DISCARD_AFTER_READERS,
                Use::COMPUTE_STORAGE,
            );
            for level in 1..=m.levels as usize {
                if level > 1 {
                    barrier::compute_to_compute(gpu, cmd);
                }
                let extent = m.level_extent(level as u32);
                match (level, &self.above) {
                    (1, _) => self.level_one.dispatch(ctx, 0, &[], extent),
                    (_, Some(above)) => above.dispatch(ctx, level - 2, &[], extent),
                    (_, None) => unreachable!("levels above 1 have their pipeline"),
                }
            }
            barrier::transition(gpu, cmd, &images, Use::COMPUTE_STORAGE, Use::READ_ONLY);
        });
    }
}
