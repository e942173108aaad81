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

/// Level 1, level 2 and the levels above are separate pipelines
/// (`geometry_mips.comp`'s specialisation constant LEVEL): CPU drivers execute
/// every branch under a lane mask, so one pipeline would run the reads and
/// stores of all three for every texel.
pub struct GeometryMipsPass {
    /// Index 0: level 1; 1: level 2 (L >= 2); 2: levels 3..=L, one descriptor
    /// set each (L >= 3).
    pipelines: Vec<ComputePass>,
}

const LEVEL: u32 = 0;

/// Shader names of the five chains' source (`src_*`) and destination (`dst_*`)
/// bindings, in `MultiresBuffer::geometry_images` order.
const SOURCES: [&str; 5] = ["src_mean", "src_normal", "src_min", "src_max", "src_flags"];
const DESTINATIONS: [&str; 5] = ["dst_mean", "dst_normal", "dst_min", "dst_max", "dst_flags"];

impl GeometryMipsPass {
    pub fn new(setup: &Setup, m: &MultiresBuffer) -> Result<Self> {
        let (t, s) = (setup.targets, setup.samplers);
        let images = m.geometry_images();
        let levels = m.levels as usize;
        // Mean, normal and flags hold levels 1..=L (mip m is level m + 1;
        // level 0 is the G-buffer); the ranges hold levels 2..=L (mip m is
        // level m + 2; levels 1 and 2 read the G-buffer). Bindings a level
        // does not use point at a mip it does not write (the last one).
        let mip_of = |image: usize, level: usize| {
            let first = if image == 2 || image == 3 { 2 } else { 1 };
            let last = images[image].mip_views.len() - 1;
            level.checked_sub(first).unwrap_or(last)
        };
        let bindings = |l: usize| {
            let mut b = vec![
                Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
                Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
            ];
            for (names, level) in [(SOURCES, l - 1), (DESTINATIONS, l)] {
                b.extend(images.iter().zip(names).enumerate().map(|(k, (i, name))| {
                    Binding::storage_image(name, i.mip_views[mip_of(k, level)])
                }));
            }
            b
        };
        let pass = |kind: i32, variants: Vec<Vec<Binding>>| {
            ComputePass::new(
                setup,
                "geometry-mips",
                "geometry_mips.comp",
                &variants,
                0,
                &[(LEVEL, kind)],
            )
        };
        let mut pipelines = vec![pass(1, vec![bindings(1)])?];
        if levels >= 2 {
            pipelines.push(pass(2, vec![bindings(2)])?);
        }
        if levels >= 3 {
            pipelines.push(pass(3, (3..=levels).map(bindings).collect())?);
        }
        Ok(Self { pipelines })
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
                let (pipeline, set) = match level {
                    1 | 2 => (level - 1, 0),
                    _ => (2, level - 3),
                };
                self.pipelines[pipeline].dispatch(ctx, set, &[], m.level_extent(level as u32));
            }
            barrier::transition(gpu, cmd, &images, Use::COMPUTE_STORAGE, Use::READ_ONLY);
        });
    }
}
