//! Pass `hisr-cut` (docs/algorithm.md section 4.4) and, with the voxel grid
//! and shared visibility, pass `hisr-visibility` (section 5.7): the part of
//! the light-tree traversal every receiver of an eye-space tile makes alike,
//! found once per tile, and the visibility of its light patches from the
//! tile's corners.

use super::gpu::{HisrCutHeader, HISR_CUT_LEVELS};
use super::{cut_bytes, cut_layout, shares_visibility, SHARED_REFINE};
use crate::frame::{FrameContext, Setup};
use crate::multires::light_source::written_for_gather;
use crate::passes::{ComputePass, INDIRECT_COMPUTE};
use crate::vk::barrier;
use crate::vk::pipeline::{Binding, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::Result;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Pass `hisr-cut` (`shaders/hisr/cut.comp`, docs/algorithm.md section 4.4):
/// one dispatch for the finest tiles' boxes of G-buffer positions, then one
/// per chained level, coarsest first, one invocation per eye-space tile.
/// Reads the G-buffer positions, the packed tree, the boxes and the coarser
/// level's cuts; writes the cut buffer (barriers in `record`).
pub struct CutPass {
    boxes: ComputePass,
    pass: ComputePass,
    /// Pass `hisr-visibility` (`shaders/hisr/visibility.comp`), with shared
    /// visibility.
    visibility: Option<ComputePass>,
    /// `--hisr-shared-refine`, for the gather.
    refine: f32,
    buffer: Buffer,
    header: HisrCutHeader,
}

impl CutPass {
    /// For the packed tree `tree`, with the run's HISR `constants`.
    pub fn new(setup: &Setup, tree: &Buffer, constants: &[Spec]) -> Result<Self> {
        let header = cut_layout(setup.settings);
        let buffer = Buffer::new(
            setup.gpu,
            "hisr-cut",
            cut_bytes(setup.settings),
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        let (t, s) = (setup.targets, setup.samplers);
        let bindings = vec![
            Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
            Binding::storage("LightTree", tree),
            Binding::storage("HisrCut", &buffer),
        ];
        let push_bytes = std::mem::size_of::<HisrCutHeader>() as u32 + 4;
        // BOXES: the boxes' dispatch or the cuts'.
        let pass = |boxes: bool| {
            let mut c = constants.to_vec();
            c.push(Spec::bool("BOXES", boxes));
            ComputePass::new(
                setup,
                "hisr-cut",
                "hisr/cut.comp",
                std::slice::from_ref(&bindings),
                push_bytes,
                &c,
            )
        };
        let visibility = match shares_visibility(setup.settings) {
            true => Some(ComputePass::new(
                setup,
                "hisr-visibility",
                "hisr/visibility.comp",
                &[vec![
                    Binding::sampled("gbuffer_position", t.gbuffer_position.view, s.nearest),
                    Binding::sampled("gbuffer_normal", t.gbuffer_normal.view, s.nearest),
                    Binding::storage("LightTree", tree),
                    Binding::storage("HisrCut", &buffer),
                ]],
                0,
                // REFINE_SPREAD: which entries get their march bit; the
                // grid's layout and march.
                &[
                    constants,
                    &[
                        Spec::float("REFINE_SPREAD", SHARED_REFINE.get(setup.settings)),
                        crate::voxel_grid::specialization(setup.settings),
                    ],
                ]
                .concat(),
            )?),
            false => None,
        };
        Ok(Self {
            boxes: pass(true)?,
            pass: pass(false)?,
            visibility,
            refine: SHARED_REFINE.get(setup.settings),
            buffer,
            header,
        })
    }

    /// The cuts' buffer (`HisrCutHeader`, counts, entries).
    pub fn buffer(&self) -> &Buffer {
        &self.buffer
    }

    /// With shared visibility (`hisr-visibility`, which the gather then
    /// interpolates), the corners' spread past which a receiver marches
    /// itself (`--hisr-shared-refine`).
    pub fn shared_refine(&self) -> Option<f32> {
        self.visibility.as_ref().map(|_| self.refine)
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let readers = vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COPY;
        profiler.pass(gpu, cmd, "hisr-cut", INDIRECT_COMPUTE, || {
            // The packed tree, just written, is read here; the previous
            // gather (of this frame's previous light view or the previous
            // frame) and readback read the cuts before they are overwritten.
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::COMPUTE_SHADER | readers,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
            );
            let push = |c: usize| {
                let mut push = bytemuck::bytes_of(&self.header).to_vec();
                push.extend_from_slice(&(c as i32).to_ne_bytes());
                push
            };
            let [tx, ty, ..] = self.header.tiles[0];
            let finest = vk::Extent2D {
                width: tx,
                height: ty,
            };
            self.boxes.dispatch(ctx, 0, &push(0), finest);
            for c in (0..HISR_CUT_LEVELS).rev() {
                // Level c reads the boxes and level c + 1's cuts.
                barrier::compute_to_compute(gpu, cmd);
                let push = push(c);
                // One invocation per tile.
                let [tx, ty, ..] = self.header.tiles[c];
                let extent = vk::Extent2D {
                    width: tx,
                    height: ty,
                };
                self.pass.dispatch(ctx, 0, &push, extent);
            }
            written_for_gather(ctx);
        });
        if let Some(visibility) = &self.visibility {
            profiler.pass(gpu, cmd, "hisr-visibility", INDIRECT_COMPUTE, || {
                // The cuts just written are read here (and the previous
                // gather's reads of the visibilities were ordered before
                // hisr-cut's first dispatch).
                barrier::compute_to_compute(gpu, cmd);
                // One workgroup of 8x8 per finest tile (frame::check
                // holds the tiles a side within the device's workgroups).
                let [tx, ty, ..] = self.header.tiles[0];
                let extent = vk::Extent2D {
                    width: 8 * tx,
                    height: 8 * ty,
                };
                visibility.dispatch(ctx, 0, &[], extent);
                written_for_gather(ctx);
            });
        }
    }
}
