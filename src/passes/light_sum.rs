//! Pass `light-sum`: adds up the direct and indirect images of a frame's
//! light views (docs/algorithm.md section 2.4), `shaders/light_sum.comp`. Every
//! view (a spot or directional light, or one cube face of a point light)
//! records its RSM, direct, light-tree and method passes as if it were the
//! only light; after each, this pass folds `direct` and `indirect` into its
//! own two sums, and after the last view writes the totals back into them.
//! Only frames with more than one view have it, so single-light frames are
//! the same commands as before lights became a list.
//! Reads and writes `direct`, `indirect` and its sums (barriers below).

use super::push_bytes;
use super::ComputePass;
use crate::frame::targets::HDR_FORMAT;
use crate::frame::{FrameContext, Setup};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::{PassKind, Profiler};
use crate::vk::{Image, ImageDesc};
use anyhow::Result;
use ash::vk;

/// It sums direct light too, so it is not an indirect-only pass.
const SUM: PassKind = PassKind {
    graphics: false,
    indirect: false,
};

/// Which view of the frame a `light-sum` pass follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SumStep {
    First = 0,
    Middle = 1,
    Last = 2,
}

pub struct LightSumPass {
    pass: ComputePass,
    direct_sum: Image,
    indirect_sum: Image,
}

impl LightSumPass {
    pub fn new(setup: &Setup) -> Result<Self> {
        let s = setup.settings;
        let extent = vk::Extent2D {
            width: s.width,
            height: s.height,
        };
        let usage = vk::ImageUsageFlags::STORAGE;
        let direct_sum = Image::new(
            setup.gpu,
            &ImageDesc::flat("direct_sum", HDR_FORMAT, extent, usage),
        )?;
        let indirect_sum = Image::new(
            setup.gpu,
            &ImageDesc::flat("indirect_sum", HDR_FORMAT, extent, usage),
        )?;
        let t = setup.targets;
        let bindings = vec![
            Binding::storage_image("direct", t.direct.view),
            Binding::storage_image("indirect", t.indirect.view),
            Binding::storage_image("direct_sum", direct_sum.view),
            Binding::storage_image("indirect_sum", indirect_sum.view),
        ];
        let pass = ComputePass::new(setup, "light-sum", "light_sum.comp", &[bindings], 4, &[])?;
        Ok(Self {
            pass,
            direct_sum,
            indirect_sum,
        })
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, step: SumStep) {
        let (gpu, cmd, t) = (ctx.gpu, ctx.cmd, ctx.targets);
        let sums = [&self.direct_sum, &self.indirect_sum];
        profiler.pass(gpu, cmd, "light-sum", SUM, || {
            // The view's outputs keep their contents (read, and written by the
            // last step). The sums start anew at the first view, after the
            // previous frame's last step read them; later steps read them back.
            let sums_from = if step == SumStep::First {
                Use::DISCARD_AFTER_READERS
            } else {
                Use::COMPUTE_STORAGE
            };
            let mut before: Vec<_> = [&t.direct, &t.indirect]
                .iter()
                .map(|i| barrier::image(i, Use::READ_ONLY, Use::COMPUTE_STORAGE))
                .collect();
            before.extend(
                sums.iter()
                    .map(|i| barrier::image(i, sums_from, Use::COMPUTE_STORAGE)),
            );
            barrier::images(gpu, cmd, &before);
            let extent = t.direct.extent;
            self.pass
                .dispatch(ctx, 0, &push_bytes(&[step as i32]), extent);
            barrier::transition(
                gpu,
                cmd,
                &[&t.direct, &t.indirect],
                Use::COMPUTE_STORAGE,
                Use::READ_ONLY,
            );
            // The sums stay in GENERAL; the next step's barrier above orders
            // its reads after these writes.
        });
    }
}
