//! Filling device-local buffers from the host. An upload records a copy and
//! the barrier after it, so it sits above `resources` (the objects) and
//! `barrier` (the commands on them), and neither of those needs the other.

use super::barrier;
use super::resources::Buffer;
use super::Gpu;
use anyhow::Result;
use ash::vk;
use gpu_allocator::MemoryLocation;

impl Buffer {
    /// A device-local buffer filled with `data` through a staging copy.
    pub fn with_data(
        gpu: &Gpu,
        name: &str,
        data: &[u8],
        usage: vk::BufferUsageFlags,
    ) -> Result<Self> {
        let dst = Self::new(
            gpu,
            name,
            data.len() as u64,
            usage | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let mut staging = Self::new(
            gpu,
            &format!("{name} (staging)"),
            data.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging.write(0, data);
        gpu.run_once(|cmd| unsafe {
            gpu.device.cmd_copy_buffer(
                cmd,
                staging.buffer,
                dst.buffer,
                &[vk::BufferCopy::default().size(data.len().max(1) as u64)],
            );
            // The copy's writes become visible to every later shader or vertex read.
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::COPY,
                vk::AccessFlags2::TRANSFER_WRITE,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                vk::AccessFlags2::MEMORY_READ,
            );
        })?;
        Ok(dst)
    }
}
