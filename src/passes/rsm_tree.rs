//! Pass `rsm-tree`: the RSM quadtree (docs/algorithm.md section 2, patches) in the
//! mip chains of the RSM images, `shaders/rsm_tree.comp`, one dispatch per
//! level, level k merging 2x2 texels of level k - 1 and flagging patches that
//! span a discontinuity.
//! Reads RSM mip 0; writes RSM mips 1.. (barriers below).
//!
//! Its parameters, the validity thresholds, matter to the methods that take
//! patches whole (`isr`, `hisr`), which list them.

use super::{ComputePass, INDIRECT_COMPUTE};
use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{self, RunUniforms};
use crate::settings::params::{AnyParam, Choices, DefaultValue, Param, Range};
use crate::settings::RenderSettings;
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use anyhow::Result;

/// A patch is valid (one surface) when each non-empty child's mean lies
/// within this fraction of its distance to the light (for an orthographic
/// RSM, of the RSM's half side) of the patch's plane...
pub const VALIDITY_DEPTH: Param<f32> = Param {
    name: "light-depth-threshold",
    help: "Light patches merge only when each child lies within this fraction of its \
           distance to the light from the merged patch's plane",
    default: DefaultValue::Fixed(0.1),
    range: Range::at_least(0.0),
};

/// ... and their normals by less than this angle (degrees).
pub const VALIDITY_NORMAL: Param<f32> = Param {
    name: "light-normal-threshold",
    help: "Light patches merge only when each child's normal is within this angle \
           (degrees) of the merged patch's",
    default: DefaultValue::Fixed(30.0),
    range: Range::closed(0.0, 180.0),
};

/// How a light patch of several RSM texels is evaluated (docs/algorithm.md
/// section 2.6, `patch_irradiance` in `shaders/vpl.glsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchKernel {
    /// At its centre, with the disc form factor: the talk's.
    Centre,
    /// With the second-order term of its texels' spread about the centre.
    SecondOrder,
}

impl Choices for PatchKernel {
    const NAMES: &'static [(&'static str, &'static str)] = &[
        (
            "centre",
            "a merged light patch lights a receiver as one disc-shaped VPL at its centre (the \
             talk's)",
        ),
        (
            "second-order",
            "the same, with the second-order term of its texels' spread over the disc added: \
             whole patches err far less at the same cost",
        ),
    ];
    fn index(self) -> usize {
        self as usize
    }
    fn from_index(i: usize) -> Self {
        [PatchKernel::Centre, PatchKernel::SecondOrder][i]
    }
}

pub const PATCH_KERNEL: Param<PatchKernel> = Param {
    name: "patch-kernel",
    help: "How a light patch of several RSM texels lights a receiver: at its centre (centre, \
           the talk's) or with the second-order term of its texels' spread (second-order); \
           single texels are the same in both",
    default: DefaultValue::Fixed(PatchKernel::SecondOrder),
    range: Range::ANY,
};

pub const PARAMS: &[&dyn AnyParam] = &[&VALIDITY_DEPTH, &VALIDITY_NORMAL, &PATCH_KERNEL];

/// The validity thresholds and the patch kernel in the run uniforms (every
/// run builds the tree).
pub fn write_uniforms(s: &RenderSettings, u: &mut RunUniforms) {
    u.validity_depth = VALIDITY_DEPTH.get(s);
    u.validity_normal_cos = VALIDITY_NORMAL.get(s).to_radians().cos();
    u.patch_kernel = match PATCH_KERNEL.get(s) {
        PatchKernel::Centre => gpu_types::PATCH_KERNEL_CENTRE,
        PatchKernel::SecondOrder => gpu_types::PATCH_KERNEL_SECOND_ORDER,
    };
}

pub struct RsmTreePass(ComputePass);

impl RsmTreePass {
    pub fn new(setup: &Setup) -> Result<Self> {
        let t = setup.targets;
        let variants: Vec<Vec<Binding>> = (1..t.rsm_position.mips as usize)
            .map(|k| {
                let (src, dst) = (k - 1, k);
                vec![
                    Binding::storage_image("src_position", t.rsm_position.mip_views[src]),
                    Binding::storage_image("src_normal", t.rsm_normal.mip_views[src]),
                    Binding::storage_image("src_flux", t.rsm_flux.mip_views[src]),
                    Binding::storage_image("dst_position", t.rsm_position.mip_views[dst]),
                    Binding::storage_image("dst_normal", t.rsm_normal.mip_views[dst]),
                    Binding::storage_image("dst_flux", t.rsm_flux.mip_views[dst]),
                ]
            })
            .collect();
        Ok(Self(ComputePass::new(
            setup,
            "rsm-tree",
            "rsm_tree.comp",
            &variants,
            0,
            &[],
        )?))
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd, t) = (ctx.gpu, ctx.cmd, ctx.targets);
        let images = [&t.rsm_position, &t.rsm_normal, &t.rsm_flux];
        let mips = t.rsm_position.mips;
        profiler.pass(gpu, cmd, "rsm-tree", INDIRECT_COMPUTE, || {
            // Level 0 (the RSM) is kept; the coarser levels are rewritten.
            let mut before = Vec::new();
            for i in images {
                before.push(barrier::mips(i, 0, 1, Use::READ_ONLY, Use::COMPUTE_STORAGE));
                before.push(barrier::mips(
                    i,
                    1,
                    mips - 1,
                    Use::DISCARD_AFTER_READERS,
                    Use::COMPUTE_STORAGE,
                ));
            }
            barrier::images(gpu, cmd, &before);
            for k in 1..mips {
                if k > 1 {
                    barrier::compute_to_compute(gpu, cmd);
                }
                self.0
                    .dispatch(ctx, k as usize - 1, &[], t.rsm_position.mip_extent(k));
            }
            barrier::transition(gpu, cmd, &images, Use::COMPUTE_STORAGE, Use::READ_ONLY);
        });
    }
}
