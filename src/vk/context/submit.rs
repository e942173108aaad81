//! Command buffers and queue submission: one-off work (`run_once`), frame
//! submissions with fences and semaphores, and what a failed submission
//! means for the user (device lost, out of memory). The fault-injection
//! test hook (`fault.rs`) sits on the one submission path.

use super::Gpu;
use anyhow::{anyhow, Result};
use ash::vk;

impl Gpu {
    pub fn allocate_command_buffer(&self) -> Result<vk::CommandBuffer> {
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        Ok(unsafe { self.device.allocate_command_buffers(&info) }?[0])
    }

    /// Submits `cmd` and blocks until the GPU has finished it.
    pub fn submit_and_wait(&self, cmd: vk::CommandBuffer) -> Result<()> {
        let fence = self.submit_fence;
        unsafe { self.device.reset_fences(&[fence]) }.map_err(submit_error)?;
        self.submit(cmd, fence)?;
        self.wait(fence)
    }

    /// Submits `cmd`; `fence` (unsignalled) is signalled when it finishes.
    pub fn submit(&self, cmd: vk::CommandBuffer, fence: vk::Fence) -> Result<()> {
        self.submit_with_semaphores(cmd, fence, None, None)
    }

    /// Submits `cmd` waiting on `wait` (at its stages) and signalling
    /// `signal` when done, besides `fence` (presentation).
    pub fn submit_with_semaphores(
        &self,
        cmd: vk::CommandBuffer,
        fence: vk::Fence,
        wait: Option<(vk::Semaphore, vk::PipelineStageFlags2)>,
        signal: Option<vk::Semaphore>,
    ) -> Result<()> {
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let waits: Vec<_> = wait
            .iter()
            .map(|&(s, stage)| {
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(s)
                    .stage_mask(stage)
            })
            .collect();
        let signals: Vec<_> = signal
            .iter()
            .map(|&s| {
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(s)
                    .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
            })
            .collect();
        let submit = [vk::SubmitInfo2::default()
            .command_buffer_infos(&cmds)
            .wait_semaphore_infos(&waits)
            .signal_semaphore_infos(&signals)];
        if let Some(e) = self.injected_fault.as_ref().and_then(|f| f.on_submit()) {
            return Err(submit_error(e));
        }
        unsafe { self.device.queue_submit2(self.queue, &submit, fence) }.map_err(submit_error)
    }

    /// Blocks until `fence` is signalled.
    pub fn wait(&self, fence: vk::Fence) -> Result<()> {
        unsafe { self.device.wait_for_fences(&[fence], true, u64::MAX) }.map_err(submit_error)
    }

    /// Records commands with `record` into a fresh command buffer, runs them and waits.
    pub fn run_once(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        let cmd = self.allocate_command_buffer()?;
        unsafe {
            self.device.begin_command_buffer(
                cmd,
                &vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )?;
        }
        record(cmd);
        let result = unsafe { self.device.end_command_buffer(cmd) }
            .map_err(anyhow::Error::from)
            .and_then(|_| self.submit_and_wait(cmd));
        unsafe { self.device.free_command_buffers(self.command_pool, &[cmd]) };
        result
    }
}

/// What a failed submission or wait means for the user.
fn submit_error(e: vk::Result) -> anyhow::Error {
    match e {
        vk::Result::ERROR_DEVICE_LOST => anyhow!(
            "the GPU device was lost (a driver timeout or crash). \
             Try a smaller --width/--height or --rsm, or a lighter method"
        ),
        vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY => {
            anyhow!("the GPU ran out of memory ({e}). Try a smaller --width/--height or --rsm")
        }
        e => anyhow!("queue submission failed: {e}"),
    }
}
