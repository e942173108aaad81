//! The frame of every method that works through the multiresolution buffer
//! (`multires-gather`, `isr`, `hisr`, `multires-splat`): [`MultiresMethod`]
//! runs the eye-space refinement once per frame, then per light view the
//! method's own light-space pass ([`LightSpacePass`]: a list of regular
//! VPLs, Basic ISR's selection, HISR's tree), the pass that fills the
//! buffer's patches ([`FillPass`]: the gather or the splat) and the
//! upsampling. [`PatchListPass`] is the light-space pass that writes a list
//! of `LightPatch`es with one dispatch.

use super::IndirectMethod;
use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{LightPatch, CHOSEN_PATCHES_HEADER};
use crate::multires::{Multires, MultiresBuffer};
use crate::passes::{ComputePass, INDIRECT_COMPUTE};
use crate::vk::barrier;
use crate::vk::pipeline::Binding;
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::Result;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// What fills the multiresolution buffer's patches: the gather or the splat.
pub trait FillPass {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, m: &MultiresBuffer);
}

/// A method's own light-space pass, recorded before the gather: Basic ISR's
/// selection, HISR's tree packing. The gather reads its buffer as
/// `ChosenPatches`.
pub trait LightSpacePass {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler);
    fn patch_buffer(&self) -> &Buffer;
    /// Basic ISR's chosen list (read back for `--stats` and tests).
    fn chosen_list(&self) -> Option<&Buffer> {
        None
    }
    /// HISR's packed light tree (read back by tests).
    fn packed_tree(&self) -> Option<&Buffer> {
        None
    }
    /// HISR's per-tile cuts (`HisrCutHeader`, counts, entries).
    fn tile_cuts(&self) -> Option<&Buffer> {
        None
    }
    /// Whether the tile cuts carry their corners' visibility
    /// (`hisr-visibility`), which the gather then interpolates, and if so
    /// the corners' spread past which a receiver marches itself
    /// (`--hisr-shared-refine`).
    fn shared_visibility_refine(&self) -> Option<f32> {
        None
    }
}

/// What a [`PatchListPass`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchList {
    /// `vpl-list`: the N regular VPLs, VPL j at entry j.
    RegularVpls,
    /// `isr-select`: the patches Basic ISR chose, appended with an atomic
    /// counter (cleared before the dispatch).
    IsrChosen,
    /// `light-tree-pack`: HISR's quadtree, a node per entry, root first.
    PackedTree,
}

/// A light-space pass that fills a buffer of `LightPatch`es (after the
/// `CHOSEN_PATCHES_HEADER`) with one compute dispatch over `extent`, which the
/// gather then reads: `vpl-list`, `isr-select`, `light-tree-pack`. Reads the
/// RSM quadtree; writes the buffer (barriers in `record`).
pub struct PatchListPass {
    name: &'static str,
    kind: PatchList,
    pass: ComputePass,
    buffer: Buffer,
    extent: vk::Extent2D,
}

impl PatchListPass {
    /// `shader` binds the RSM quadtree as `rsm_position`, `rsm_normal`,
    /// `rsm_flux` and the buffer, room for `patches`, as `buffer_name`.
    pub fn new(
        setup: &Setup,
        kind: PatchList,
        (name, shader, buffer_name): (&'static str, &str, &'static str),
        patches: u64,
        extent: vk::Extent2D,
    ) -> Result<Self> {
        let (gpu, t, s) = (setup.gpu, setup.targets, setup.samplers);
        let buffer = Buffer::new(
            gpu,
            name,
            CHOSEN_PATCHES_HEADER as u64 + patches * std::mem::size_of::<LightPatch>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::TRANSFER_SRC
                | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let bindings = vec![
            Binding::sampled("rsm_position", t.rsm_position.view, s.nearest),
            Binding::sampled("rsm_normal", t.rsm_normal.view, s.nearest),
            Binding::sampled("rsm_flux", t.rsm_flux.view, s.nearest),
            Binding::storage(buffer_name, &buffer),
        ];
        let pass = ComputePass::new(setup, name, shader, &[bindings], 0, &[])?;
        Ok(Self {
            name,
            kind,
            pass,
            buffer,
            extent,
        })
    }
}

impl LightSpacePass for PatchListPass {
    fn patch_buffer(&self) -> &Buffer {
        &self.buffer
    }

    fn chosen_list(&self) -> Option<&Buffer> {
        (self.kind == PatchList::IsrChosen).then_some(&self.buffer)
    }

    fn packed_tree(&self) -> Option<&Buffer> {
        (self.kind == PatchList::PackedTree).then_some(&self.buffer)
    }

    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let readers = vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COPY;
        let rw = vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
        profiler.pass(gpu, cmd, self.name, INDIRECT_COMPUTE, || {
            // The previous gather (fragment; of this frame's previous light
            // view or of the previous frame) and readback (copy) read the
            // buffer before it is overwritten.
            if self.kind == PatchList::IsrChosen {
                barrier::zero_buffer(
                    gpu,
                    cmd,
                    self.buffer.buffer,
                    4,
                    (readers, vk::AccessFlags2::NONE),
                    (vk::PipelineStageFlags2::COMPUTE_SHADER, rw),
                );
            } else {
                barrier::memory(
                    gpu,
                    cmd,
                    readers,
                    vk::AccessFlags2::NONE,
                    vk::PipelineStageFlags2::COMPUTE_SHADER,
                    vk::AccessFlags2::SHADER_STORAGE_WRITE,
                );
            }
            self.pass.dispatch(ctx, 0, &[], self.extent);
            written_for_gather(ctx);
        });
    }
}

/// Barrier after a light-space pass: what it wrote (compute) is read by the
/// gather (fragment) and by readback (copy).
pub fn written_for_gather(ctx: &FrameContext) {
    barrier::memory(
        ctx.gpu,
        ctx.cmd,
        vk::PipelineStageFlags2::COMPUTE_SHADER,
        vk::AccessFlags2::SHADER_STORAGE_WRITE,
        vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COPY,
        vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::TRANSFER_READ,
    );
}

/// A method that works through the multiresolution buffer: `multires-gather`,
/// `isr`, `hisr` and `multires-splat`. Geometry mips and stencil refinement
/// once per frame (`record_eye_space`); per light view the method's own
/// light-space pass, the gather or splat, then upsampling.
pub struct MultiresMethod {
    pub multires: Multires,
    light_pass: Option<Box<dyn LightSpacePass>>,
    fill: Box<dyn FillPass>,
}

impl MultiresMethod {
    /// `fill` makes the pass that fills the buffer's patches, given the
    /// buffer and the light-space pass (if there is one).
    pub fn new(
        setup: &Setup,
        light_pass: Option<Box<dyn LightSpacePass>>,
        fill: impl FnOnce(
            &Setup,
            &MultiresBuffer,
            Option<&dyn LightSpacePass>,
        ) -> Result<Box<dyn FillPass>>,
    ) -> Result<Self> {
        let multires = Multires::new(setup)?;
        let fill = fill(setup, &multires.buffer, light_pass.as_deref())?;
        Ok(Self {
            multires,
            light_pass,
            fill,
        })
    }
}

impl IndirectMethod for MultiresMethod {
    fn record_eye_space(&self, ctx: &FrameContext, p: &mut Profiler) {
        self.multires.record_refinement(ctx, p);
    }

    fn record(&self, ctx: &FrameContext, p: &mut Profiler, _: usize) {
        if let Some(l) = &self.light_pass {
            l.record(ctx, p);
        }
        self.fill.record(ctx, p, &self.multires.buffer);
        self.multires.record_upsample(ctx, p);
    }

    fn multires(&self) -> Option<&MultiresBuffer> {
        Some(&self.multires.buffer)
    }

    fn chosen_patches(&self) -> Option<&Buffer> {
        self.light_pass.as_ref().and_then(|l| l.chosen_list())
    }

    fn packed_light_tree(&self) -> Option<&Buffer> {
        self.light_pass.as_ref().and_then(|l| l.packed_tree())
    }
}
