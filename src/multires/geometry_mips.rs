//! Pass `geometry-mips`: levels 0..=L of the geometry mipmaps (ALGORITHM.md
//! section 3, steps 2-4) with `shaders/geometry_mips.comp`, one dispatch per
//! level. Reads the G-buffer; writes `geo_*` (barriers below).

use super::MultiresBuffer;
use crate::passes::{ComputePass, FrameContext, INDIRECT_COMPUTE};
use crate::renderer::{Samplers, Targets};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::Result;

pub struct GeometryMipsPass(ComputePass);

impl GeometryMipsPass {
    pub fn new(
        gpu: &Gpu,
        uniforms: &Buffer,
        t: &Targets,
        s: &Samplers,
        m: &MultiresBuffer,
    ) -> Result<Self> {
        let images = m.geometry_images();
        let variants: Vec<Vec<Binding>> = (0..=m.levels as usize)
            .map(|l| {
                let mut b = vec![
                    Binding::Uniform(uniforms),
                    Binding::Sampled(t.gbuffer_position.view, s.nearest),
                    Binding::Sampled(t.gbuffer_normal.view, s.nearest),
                ];
                // Level 0 has no source level; its source bindings are unused.
                let src = l.saturating_sub(1);
                b.extend(
                    images
                        .iter()
                        .map(|i| Binding::StorageImage(i.mip_views[src])),
                );
                b.extend(images.iter().map(|i| Binding::StorageImage(i.mip_views[l])));
                b
            })
            .collect();
        Ok(Self(ComputePass::new(
            gpu,
            "geometry-mips",
            "geometry_mips.comp",
            &variants,
            4,
            &[],
        )?))
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
            for level in 0..=m.levels {
                if level > 0 {
                    barrier::compute_to_compute(gpu, cmd);
                }
                let push = (level as i32).to_ne_bytes();
                self.0.dispatch(
                    gpu,
                    cmd,
                    level as usize,
                    &push,
                    m.geo_flags.mip_extent(level),
                );
            }
            barrier::transition(gpu, cmd, &images, Use::COMPUTE_STORAGE, Use::READ_ONLY);
        });
    }

    pub fn destroy(&mut self, gpu: &Gpu) {
        self.0.destroy(gpu);
    }
}
