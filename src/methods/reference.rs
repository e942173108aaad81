//! Method `reference` (docs/algorithm.md section 5): every pixel gathers every RSM
//! texel (N = R^2 VPLs) at full resolution, the converged limit of the
//! approximation. The work is split into bands of VPLs, one submission each
//! (`IndirectMethod::submissions`; the renderer starts a new command buffer per chunk), so no submission runs
//! long enough to trip a driver's timeout; each band adds into `indirect`.
//! Pass `reference` (once per chunk; the report sums them). Its time runs from
//! the previous chunk's end-of-pass timestamp, in the previous submission, so
//! it includes the gaps between submissions (fence wait, next submit): small
//! against lavapipe's half-second chunks, not against a GPU's milliseconds.
//! A start-of-submission timestamp would exclude them on a GPU, but lavapipe
//! reads a timestamp written before a pass near that pass's end, so there it
//! would measure nothing. The reference is a ground truth, not a real-time
//! method; its time is informational.
//!
//! `shaders/rsm_gather/gather.frag` with additive blending. Reads the G-buffer and
//! RSM; writes `indirect` (barriers below).

use super::rsm_gather::full_resolution_bindings;
use super::rsm_splat::require_blending;
use super::{Descriptor, IndirectMethod};
use crate::frame::{FrameContext, Setup};
use crate::passes::{begin_rendering, push_bytes, Attachments, INDIRECT_GRAPHICS};
use crate::regular_vpls::RegularVpls;
use crate::settings::params::{AnyParam, DefaultValue, Param, Range};
use crate::settings::{Method, RenderSettings};
use crate::visibility;
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Blend, GraphicsDesc, PassPipeline};
use crate::vk::profiler::Profiler;
use anyhow::Result;
use ash::vk;

pub const KEY: Method = Method::new("reference");

/// The reference's light-patch evaluations per submission.
pub const CHUNK: Param<u64> = Param {
    name: "reference-chunk",
    help: "--method reference: light-patch evaluations per submission (pixels x VPLs). \
           The default keeps a submission near half a second on lavapipe; on a GPU, \
           larger chunks cut the per-submission overhead",
    default: DefaultValue::Fixed(1 << 26),
    range: Range::at_least(1.0),
};

const PARAMS: &[&dyn AnyParam] = &[&CHUNK];

pub struct ReferenceMethod;

impl Descriptor for ReferenceMethod {
    fn key(&self) -> Method {
        KEY
    }
    fn help(&self) -> &'static str {
        "Every pixel gathers every RSM texel (R^2 VPLs), in chunks."
    }
    fn params(&self) -> &'static [&'static [&'static dyn AnyParam]] {
        // Its VPLs are every RSM texel: --vpls and --vpl-sampling do not apply.
        &[PARAMS]
    }
    fn reads_visibility(&self) -> bool {
        true
    }
    /// `--visibility exact`: the CPU gather of `visibility` replaces this
    /// one's image after the frame.
    fn takes_exact_visibility(&self) -> bool {
        true
    }
    /// Many submissions a frame: seconds on lavapipe, not for a window.
    fn interactive(&self) -> bool {
        false
    }
    fn evaluations_per_pixel(&self, s: &RenderSettings) -> Option<u64> {
        Some(RegularVpls::every_texel(s).count as u64)
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        Ok(Box::new(Reference::new(setup)?))
    }
}

pub struct Reference {
    pipeline: PassPipeline,
    /// VPL ranges [first, last) in row-major RSM order, one per submission.
    pub chunks: Vec<(u32, u32)>,
}

impl Reference {
    /// Chunks of at most `--reference-chunk` light-patch evaluations
    /// (pixels x VPLs) each.
    pub fn new(setup: &Setup) -> Result<Self> {
        let s = setup.settings;
        let format = setup.targets.indirect.format;
        require_blending(setup.gpu, format, "reference")?;
        let pipeline = PassPipeline::graphics(
            setup.gpu,
            setup.frame,
            &full_resolution_bindings(setup),
            GraphicsDesc {
                name: "reference",
                fragment_shader: "rsm_gather/gather.frag",
                push_constant_bytes: 8,
                color_formats: &[format],
                blend: Blend::Additive,
                specialization: &[
                    &crate::visibility::specialization(s)[..],
                    &RegularVpls::every_texel(s).specialization(s),
                ]
                .concat(),
                ..Default::default()
            },
        )?;
        let total = RegularVpls::every_texel(s).count;
        let pixels = s.width as u64 * s.height as u64;
        let mut per_chunk = (CHUNK.get(s).max(1) / pixels).clamp(1, total as u64) as u32;
        if visibility::uses_voxels(s) {
            // A fragment's marches through the grid within lavapipe's loop
            // limit (`visibility::LOOP_BUDGET`).
            let most = visibility::LOOP_BUDGET / visibility::LOOP_ITERATIONS_PER_EVALUATION;
            per_chunk = per_chunk.min(most as u32);
        }
        let chunks = (0..total.div_ceil(per_chunk))
            .map(|c| (c * per_chunk, ((c + 1) * per_chunk).min(total)))
            .collect();
        Ok(Self { pipeline, chunks })
    }
}

impl IndirectMethod for Reference {
    fn submissions(&self) -> usize {
        self.chunks.len()
    }

    /// Records chunk `i` into `ctx.cmd` (its own command buffer).
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, i: usize) {
        let (gpu, cmd, indirect) = (ctx.gpu, ctx.cmd, &ctx.targets.indirect);
        let (first, last) = self.chunks[i];
        let push = push_bytes(&[first as i32, last as i32]);
        profiler.pass(gpu, cmd, "reference", INDIRECT_GRAPHICS, || unsafe {
            if i == 0 {
                // Cleared once; every chunk then adds its band of VPLs.
                barrier::clear_color(gpu, cmd, indirect, Use::COLOR_ATTACHMENT);
            } else {
                // The previous chunk's blended writes, from the previous submission.
                barrier::transition(
                    gpu,
                    cmd,
                    &[indirect],
                    Use::COLOR_ATTACHMENT,
                    Use::COLOR_ATTACHMENT,
                );
            }
            begin_rendering(
                gpu,
                cmd,
                // Blended onto the previous chunks' sums (cleared before the first).
                &Attachments::loaded(&[indirect.view], indirect.extent),
            );
            self.pipeline.bind(gpu, cmd, ctx.frame_set);
            gpu.device.cmd_push_constants(
                cmd,
                self.pipeline.pipeline.layout,
                vk::ShaderStageFlags::ALL_GRAPHICS,
                0,
                &push,
            );
            gpu.device.cmd_draw(cmd, 3, 1, 0, 0);
            gpu.device.cmd_end_rendering(cmd);
            if i + 1 == self.chunks.len() {
                barrier::transition(gpu, cmd, &[indirect], Use::COLOR_ATTACHMENT, Use::READ_ONLY);
            }
        });
    }
}
