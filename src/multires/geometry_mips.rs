//! Pass `geometry-mips`: levels 1..=L of the geometry mipmaps (docs/algorithm.md
//! section 3, steps 2-4), one full-screen draw per level into that level's mip
//! of the five chains (level 0 is the G-buffer itself):
//! `shaders/multires/geometry_level_one.frag` reads the G-buffer,
//! `shaders/multires/geometry_mips.frag` level l - 1 (`shaders/multires/geometry_mips.glsl`).
//! Reads the G-buffer; writes `geo_*` (barriers below).

use super::MultiresBuffer;
use crate::frame::{FrameContext, Setup};
use crate::passes::{begin_rendering, Attachments, INDIRECT_GRAPHICS};
use crate::vk::barrier::{self, Use};
use crate::vk::descriptors::DescriptorSet;
use crate::vk::pipeline::{Binding, GraphicsDesc, PassPipeline, Pipeline};
use crate::vk::profiler::Profiler;
use anyhow::Result;
use ash::vk;

/// Level 1 and the levels above are separate shaders: CPU drivers execute
/// every branch under a lane mask, so one shader would run the reads of both
/// for every texel.
pub struct GeometryMipsPass {
    level_one: PassPipeline,
    /// Levels 2..=L, one descriptor set each (none with L = 1).
    above: Option<(Pipeline, Vec<DescriptorSet>)>,
}

/// Shader names of the five chains' source bindings, in
/// `MultiresBuffer::geometry_images` order (the outputs are in that order too).
const SOURCES: [&str; 5] = ["src_mean", "src_normal", "src_min", "src_max", "src_flags"];

impl GeometryMipsPass {
    pub fn new(setup: &Setup, m: &MultiresBuffer) -> Result<Self> {
        let (gpu, t, s) = (setup.gpu, setup.targets, setup.samplers);
        let images = m.geometry_images();
        let color_formats = images.map(|i| i.format);
        let desc = |shader| GraphicsDesc {
            name: "geometry-mips",
            fragment_shader: shader,
            color_formats: &color_formats,
            ..Default::default()
        };
        let level_one = PassPipeline::graphics(
            gpu,
            setup.frame,
            &[
                Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
                Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
            ],
            desc("multires/geometry_level_one.frag"),
        )?;
        // Level l (2..=L) reads mip l - 2, level l - 1 (mip m is level m + 1).
        let above_sets = (2..=m.levels as usize)
            .map(|l| {
                let bindings: Vec<_> = images
                    .iter()
                    .zip(SOURCES)
                    .map(|(i, name)| Binding::storage_image(name, i.mip_views[l - 2]))
                    .collect();
                DescriptorSet::new(gpu, "geometry-mips", &bindings)
            })
            .collect::<Result<Vec<_>>>()?;
        // One pipeline for all of them (their sets' layouts are alike).
        let above = match above_sets.first() {
            Some(first) => {
                let sets = &[setup.frame, first];
                let pipeline = Pipeline::graphics(
                    gpu,
                    &GraphicsDesc {
                        sets,
                        ..desc("multires/geometry_mips.frag")
                    },
                )?;
                Some((pipeline, above_sets))
            }
            None => None,
        };
        Ok(Self { level_one, above })
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let images = m.geometry_images();
        profiler.pass(gpu, cmd, "geometry-mips", INDIRECT_GRAPHICS, || {
            barrier::transition(
                gpu,
                cmd,
                &images,
                Use::DISCARD_AFTER_READERS,
                Use::COLOR_ATTACHMENT,
            );
            for level in 1..=m.levels {
                let mip = level - 1;
                if level > 1 {
                    // The previous level, written as attachments, is read
                    // as storage images by this draw.
                    let before: Vec<_> = images
                        .iter()
                        .map(|i| {
                            barrier::mips(
                                i,
                                mip - 1,
                                1,
                                Use::COLOR_ATTACHMENT,
                                Use::FRAGMENT_STORAGE,
                            )
                        })
                        .collect();
                    barrier::images(gpu, cmd, &before);
                }
                let views = images.map(|i| i.mip_views[mip as usize]);
                begin_rendering(
                    gpu,
                    cmd,
                    // Every texel is written: nothing to clear.
                    &Attachments::loaded(&views, m.level_extent(level)),
                );
                match (level, &self.above) {
                    (1, _) => self.level_one.bind(gpu, cmd, ctx.frame_set),
                    (_, Some((above, sets))) => above.bind(
                        gpu,
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        &[ctx.frame_set, sets[level as usize - 2].set],
                    ),
                    (_, None) => unreachable!("levels above 1 have their pipeline"),
                }
                unsafe {
                    gpu.device.cmd_draw(cmd, 3, 1, 0, 0);
                    gpu.device.cmd_end_rendering(cmd);
                }
            }
            // Mips 0..L-2 were last read as storage images, mip L-1 written.
            let last = m.levels - 1;
            let mut after: Vec<_> = images
                .iter()
                .map(|i| barrier::mips(i, last, 1, Use::COLOR_ATTACHMENT, Use::READ_ONLY))
                .collect();
            if last > 0 {
                after.extend(
                    images
                        .iter()
                        .map(|i| barrier::mips(i, 0, last, Use::FRAGMENT_STORAGE, Use::READ_ONLY)),
                );
            }
            barrier::images(gpu, cmd, &after);
        });
    }
}
