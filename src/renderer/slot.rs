//! One frame in flight (`Slot`): what a frame that may still be running on
//! the GPU owns, so that the next frame can be recorded beside it.

use crate::frame::FrameSet;
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::Result;
use ash::vk;
use std::time::Instant;

/// One frame in flight: its frame sets (one per light view), command
/// buffers, queries and fence.
pub(super) struct Slot<'g> {
    gpu: &'g Gpu,
    pub(super) frames: Vec<FrameSet>,
    pub(super) profiler: Profiler,
    pub(super) cmds: Vec<vk::CommandBuffer>,
    pub(super) fence: vk::Fence,
    /// The frame this slot holds while it is in flight, and when it was submitted.
    pub(super) in_flight: Option<(u32, Instant)>,
}

impl<'g> Slot<'g> {
    pub(super) fn new(
        gpu: &'g Gpu,
        (run, grid): (&Buffer, &Buffer),
        instances: usize,
        views: usize,
        passes: u32,
    ) -> Result<Self> {
        let frames = (0..views)
            .map(|_| FrameSet::new(gpu, run, grid, instances))
            .collect::<Result<Vec<_>>>()?;
        let profiler = Profiler::new(gpu, passes)?;
        let fence = unsafe {
            gpu.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }?;
        Ok(Self {
            gpu,
            frames,
            profiler,
            cmds: Vec::new(),
            fence,
            in_flight: None,
        })
    }

    /// `n` command buffers, allocated on first use and reused after.
    pub(super) fn command_buffers(&mut self, n: usize) -> Result<&[vk::CommandBuffer]> {
        while self.cmds.len() < n {
            let cmd = self.gpu.allocate_command_buffer()?;
            self.cmds.push(cmd);
        }
        Ok(&self.cmds[..n])
    }
}

impl Drop for Slot<'_> {
    fn drop(&mut self) {
        let d = &self.gpu.device;
        unsafe {
            if self.in_flight.is_some() {
                let _ = d.wait_for_fences(&[self.fence], true, u64::MAX);
            }
            if !self.cmds.is_empty() {
                d.free_command_buffers(self.gpu.command_pool, &self.cmds);
            }
            d.destroy_fence(self.fence, None);
        }
    }
}
