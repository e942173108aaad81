//! Method `isr` (Basic image-space radiosity, docs/algorithm.md section 4): per
//! frame, the largest valid patches of the RSM quadtree above a dense base
//! level, compacted on the GPU into one list that every eye-space patch
//! gathers from (`methods::gather`).
//!
//! Pass `isr-select`: `shaders/isr_select.comp`, one dispatch over the base
//! level with an atomic append. Reads the RSM quadtree; writes the chosen list.

use super::gather::{GatherPass, LightPatches, LightSpacePass, MultiresMethod};
use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{LightPatch, CHOSEN_PATCHES_HEADER};
use crate::passes::{ComputePass, INDIRECT_COMPUTE};
use crate::vk::barrier;
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::{anyhow, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Method `isr`: the selection, then every eye-space patch gathers the list.
pub fn new(setup: &Setup) -> Result<MultiresMethod> {
    let select = IsrSelectPass::new(setup)?;
    MultiresMethod::new(setup, Some(Box::new(select)), |setup, m, chosen| {
        let chosen = chosen.ok_or_else(|| anyhow!("isr gathers from its chosen list"))?;
        Ok(Box::new(GatherPass::new(
            setup,
            m,
            LightPatches::List,
            chosen,
        )?))
    })
}

pub struct IsrSelectPass {
    pass: ComputePass,
    /// `uint count; uint pad[3]; LightPatch patches[]`, room for every base texel.
    pub chosen: Buffer,
    base_extent: vk::Extent2D,
}

impl IsrSelectPass {
    pub fn new(setup: &Setup) -> Result<Self> {
        let (gpu, t, s) = (setup.gpu, setup.targets, setup.samplers);
        // The RSM quadtree level to start from (also in the run uniforms).
        let base_mip = setup.settings.isr_base_mip();
        // At most one chosen patch per base texel.
        let base_extent = t.rsm_position.mip_extent(base_mip);
        let base_texels = base_extent.width as u64 * base_extent.height as u64;
        let chosen = Buffer::new(
            gpu,
            "isr chosen patches",
            CHOSEN_PATCHES_HEADER as u64 + base_texels * std::mem::size_of::<LightPatch>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        let bindings = vec![
            Binding::sampled("rsm_position", t.rsm_position.view, s.nearest),
            Binding::sampled("rsm_normal", t.rsm_normal.view, s.nearest),
            Binding::sampled("rsm_flux", t.rsm_flux.view, s.nearest),
            Binding::storage("ChosenPatches", &chosen),
        ];
        let pass = ComputePass::new(setup, "isr-select", "isr_select.comp", &[bindings], 0, &[])?;
        Ok(Self {
            pass,
            chosen,
            base_extent,
        })
    }
}

impl LightSpacePass for IsrSelectPass {
    fn buffer(&self) -> &Buffer {
        &self.chosen
    }

    fn chosen_list(&self) -> Option<&Buffer> {
        Some(&self.chosen)
    }

    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let rw = vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
        profiler.pass(gpu, cmd, "isr-select", INDIRECT_COMPUTE, || unsafe {
            // The previous frame's gather (fragment) and readback (copy) read the list.
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COPY,
                vk::AccessFlags2::NONE,
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::AccessFlags2::TRANSFER_WRITE,
            );
            gpu.device.cmd_fill_buffer(cmd, self.chosen.buffer, 0, 4, 0);
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::AccessFlags2::TRANSFER_WRITE,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                rw,
            );
            // One invocation per base texel.
            self.pass.dispatch(ctx, 0, &[], self.base_extent);
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
