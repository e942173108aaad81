//! What a method that gathers into the multiresolution buffer brings to it:
//! a light-space source ([`LightSource`], docs/algorithm.md section 4), the
//! passes that choose this light view's light patches and the part of the
//! gather's fragment shader that visits them. The framework knows no source
//! by name: the regular VPLs (`regular_vpls`), Basic ISR and HISR each
//! provide one.
//!
//! [`PatchList`] is the source that writes a list of `LightPatch`es with one
//! compute dispatch, which every eye-space patch then evaluates whole
//! (`shaders/multires/gather_list.frag`).

use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{LightPatch, LIGHT_PATCHES_HEADER};
use crate::passes::{ComputePass, INDIRECT_COMPUTE};
use crate::vk::barrier;
use crate::vk::pipeline::{Binding, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::Result;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// The light patches a source offers the gather in one frame: a buffer of
/// `LIGHT_PATCHES_HEADER` (the count) then `LightPatch`es, read back by tests
/// and `--stats`.
pub struct LightPatches<'a> {
    pub buffer: &'a Buffer,
    /// Whether the source chooses them anew every frame (so their count is
    /// worth reporting), rather than laying out a fixed set.
    pub chosen_per_frame: bool,
}

/// A method's light-space source.
pub trait LightSource {
    /// Records its passes for one light view, before the gather, with their
    /// barriers: the gather's fragment shader reads what they write.
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler);

    /// The gather's fragment shader (`shaders/<source>/...`): it includes
    /// `multires/gather.glsl` and defines `gather_patches`.
    fn gather_shader(&self) -> &'static str;

    /// Its bindings of the gather's set 1, from `gather::SOURCE_BINDING` on.
    fn gather_bindings(&self) -> Vec<Binding<'_>>;

    /// Its specialization constants of the gather, besides visibility's.
    fn gather_constants(&self) -> Vec<Spec>;

    /// The light patches of the last frame.
    fn light_patches(&self) -> LightPatches<'_>;
}

/// A source that writes a list of light patches with one compute dispatch
/// over `extent` that reads the RSM quadtree (the regular VPLs' list, Basic
/// ISR's chosen patches), gathered whole by every eye-space patch
/// (`shaders/multires/gather_list.frag`).
pub struct PatchList {
    name: &'static str,
    /// Whether the list is appended with an atomic counter, which is
    /// cleared before the dispatch.
    appended: bool,
    pass: ComputePass,
    buffer: Buffer,
    extent: vk::Extent2D,
}

impl PatchList {
    /// Pass `name` runs `shader`, which binds the RSM quadtree as
    /// `rsm_position`, `rsm_normal`, `rsm_flux` and the list, room for
    /// `patches`, as `LightPatches`, with its specialization `constants`.
    pub fn new(
        setup: &Setup,
        (name, shader, constants): (&'static str, &str, &[Spec]),
        appended: bool,
        patches: u64,
        extent: vk::Extent2D,
    ) -> Result<Self> {
        let (gpu, t, s) = (setup.gpu, setup.targets, setup.samplers);
        let buffer = Buffer::new(
            gpu,
            name,
            LIGHT_PATCHES_HEADER as u64 + patches * std::mem::size_of::<LightPatch>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::TRANSFER_SRC
                | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let bindings = vec![
            Binding::sampled("rsm_position", t.rsm_position.view, s.nearest),
            Binding::sampled("rsm_normal", t.rsm_normal.view, s.nearest),
            Binding::sampled("rsm_flux", t.rsm_flux.view, s.nearest),
            Binding::storage("LightPatches", &buffer),
        ];
        let pass = ComputePass::new(setup, name, shader, &[bindings], 0, constants)?;
        Ok(Self {
            name,
            appended,
            pass,
            buffer,
            extent,
        })
    }

    /// The list's buffer.
    pub fn buffer(&self) -> &Buffer {
        &self.buffer
    }

    /// Records the dispatch into `ctx`, with its barriers: the previous
    /// gather (of this frame's previous light view or of the previous frame)
    /// and readback read the list before it is overwritten.
    pub fn record_list(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let readers = vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COPY;
        let rw = vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
        profiler.pass(gpu, cmd, self.name, INDIRECT_COMPUTE, || {
            if self.appended {
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

impl LightSource for PatchList {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        self.record_list(ctx, profiler);
    }

    fn gather_shader(&self) -> &'static str {
        "multires/gather_list.frag"
    }

    fn gather_bindings(&self) -> Vec<Binding<'_>> {
        vec![Binding::storage("LightPatches", &self.buffer)]
    }

    fn gather_constants(&self) -> Vec<Spec> {
        vec![]
    }

    fn light_patches(&self) -> LightPatches<'_> {
        LightPatches {
            buffer: &self.buffer,
            chosen_per_frame: self.appended,
        }
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
