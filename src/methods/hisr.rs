//! Method `hisr` (Hierarchical image-space radiosity, docs/algorithm.md
//! section 4): every eye-space patch traverses the RSM quadtree itself,
//! subdividing light patches whose contribution could exceed tau. The
//! traversal is in `shaders/gather.frag` (`traverse`, with the derivation of
//! the bound) and reads the quadtree packed into one buffer by the pass
//! below; this module makes the method and holds its constants.

use super::gather::{GatherPass, LightPatches, LightSpacePass, MultiresMethod};
use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{LightPatch, CHOSEN_PATCHES_HEADER};
use crate::passes::{ComputePass, INDIRECT_COMPUTE};
use crate::vk::barrier;
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::Result;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Method `hisr`: the tree is packed, then the gather traverses it per fragment.
pub fn new(setup: &Setup) -> Result<MultiresMethod> {
    let pack = LightTreePackPass::new(setup)?;
    MultiresMethod::new(setup, Some(Box::new(pack)), |setup, m, tree| {
        Ok(Box::new(GatherPass::new(
            setup,
            m,
            LightPatches::Traversal,
            tree,
        )?))
    })
}

/// Pass `light-tree-pack`: `shaders/light_tree_pack.comp`, one dispatch that
/// copies every node of the RSM quadtree into one buffer. Reads the quadtree;
/// writes the buffer the gather traverses.
pub struct LightTreePackPass {
    pass: ComputePass,
    tree: Buffer,
    /// One invocation per node: R wide, enough rows for (4 R^2 - 1) / 3 nodes.
    extent: vk::Extent2D,
}

impl LightTreePackPass {
    pub fn new(setup: &Setup) -> Result<Self> {
        let (gpu, t, s) = (setup.gpu, setup.targets, setup.samplers);
        let r = setup.settings.rsm_resolution as u64;
        let nodes = (4 * r * r - 1) / 3;
        let tree = Buffer::new(
            gpu,
            "hisr light tree",
            CHOSEN_PATCHES_HEADER as u64 + nodes * std::mem::size_of::<LightPatch>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        let bindings = vec![
            Binding::sampled("rsm_position", t.rsm_position.view, s.nearest),
            Binding::sampled("rsm_normal", t.rsm_normal.view, s.nearest),
            Binding::sampled("rsm_flux", t.rsm_flux.view, s.nearest),
            Binding::storage("LightTree", &tree),
        ];
        let pass = ComputePass::new(
            setup,
            "light-tree-pack",
            "light_tree_pack.comp",
            &[bindings],
            0,
            &[],
        )?;
        let extent = vk::Extent2D {
            width: r as u32,
            height: nodes.div_ceil(r) as u32,
        };
        Ok(Self { pass, tree, extent })
    }
}

impl LightSpacePass for LightTreePackPass {
    fn buffer(&self) -> &Buffer {
        &self.tree
    }

    fn packed_tree(&self) -> Option<&Buffer> {
        Some(&self.tree)
    }

    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        profiler.pass(gpu, cmd, "light-tree-pack", INDIRECT_COMPUTE, || {
            // The previous frame's gather (fragment) and readback (copy) read
            // the buffer before it is overwritten.
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COPY,
                vk::AccessFlags2::NONE,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
            );
            self.pass.dispatch(ctx, 0, &[], self.extent);
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
                vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COPY,
                vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::TRANSFER_READ,
            );
        });
    }
}

/// T at the finest level for `tau` given as a fraction of the light's peak
/// intensity I: T = 2 (I - tau I) / (3 tau I R^2) = 2 (1 - tau) / (3 tau R^2).
pub fn subdivision_threshold(tau: f32, rsm_resolution: u32) -> f32 {
    let r2 = rsm_resolution as f64 * rsm_resolution as f64;
    (2.0 * (1.0 - tau as f64) / (3.0 * tau as f64 * r2)) as f32
}

#[cfg(test)]
mod tests {
    use super::subdivision_threshold;

    #[test]
    fn threshold_falls_as_tau_grows_and_vanishes_at_one() {
        let t = |tau| subdivision_threshold(tau, 256);
        assert!(t(0.001) > t(0.01) && t(0.01) > t(0.1));
        assert_eq!(t(1.0), 0.0);
        // tau = 1/3 at R = 1: T = 2 (2/3) / 1 = 4/3.
        assert!((subdivision_threshold(1.0 / 3.0, 1) - 4.0 / 3.0).abs() < 1e-6);
    }
}
