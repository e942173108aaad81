//! Small synchronization2 helpers. Passes call these right beside the draws they
//! guard, so every barrier is read where it matters.
//!
//! The convention every pass follows (see `passes/mod.rs`): a pass first makes
//! its outputs writable (discarding old contents, after earlier readers are done),
//! and when it has finished it leaves every image it wrote in
//! `SHADER_READ_ONLY_OPTIMAL`, with its writes visible to the stages in
//! [`READERS`]. Consumers therefore need no barrier for their inputs.

use super::resources::Image;
use super::Gpu;
use ash::vk;

/// Every stage that may read a finished pass output: vertex (splats fetch
/// their VPL there), fragment and compute shaders, and the readback copy.
pub const READERS: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::from_raw(
    vk::PipelineStageFlags2::VERTEX_SHADER.as_raw()
        | vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw()
        | vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw()
        | vk::PipelineStageFlags2::COPY.as_raw(),
);
pub const READ_ACCESS: vk::AccessFlags2 = vk::AccessFlags2::from_raw(
    vk::AccessFlags2::SHADER_SAMPLED_READ.as_raw()
        | vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
        | vk::AccessFlags2::TRANSFER_READ.as_raw(),
);

/// Where and how an image is used on one side of a barrier.
#[derive(Clone, Copy, Debug)]
pub struct Use {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
    pub layout: vk::ImageLayout,
}

impl Use {
    /// Contents are discarded; waits for the previous readers (write-after-read).
    pub const DISCARD_AFTER_READERS: Use = Use {
        stage: READERS,
        access: vk::AccessFlags2::NONE,
        layout: vk::ImageLayout::UNDEFINED,
    };
    pub const COLOR_ATTACHMENT: Use = Use {
        stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw()
                | vk::AccessFlags2::COLOR_ATTACHMENT_READ.as_raw(),
        ),
        layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    };
    pub const DEPTH_ATTACHMENT: Use = Use {
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
        ),
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw(),
        ),
        layout: vk::ImageLayout::ATTACHMENT_OPTIMAL,
    };
    /// Storage-image reads and writes by compute shaders.
    pub const COMPUTE_STORAGE: Use = Use {
        stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
                | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
        ),
        layout: vk::ImageLayout::GENERAL,
    };
    /// Storage-image reads and writes by fragment shaders.
    pub const FRAGMENT_STORAGE: Use = Use {
        stage: vk::PipelineStageFlags2::FRAGMENT_SHADER,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
                | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
        ),
        layout: vk::ImageLayout::GENERAL,
    };
    /// A stencil buffer written by stencil operations.
    pub const STENCIL_ATTACHMENT: Use = Use::DEPTH_ATTACHMENT;
    /// The stencil's resting state after it is written: read-only by stencil
    /// tests and copies. (Not `SHADER_READ_ONLY_OPTIMAL`: S8 need not be sampleable.)
    pub const STENCIL_READ_ONLY: Use = Use {
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::COPY.as_raw(),
        ),
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw()
                | vk::AccessFlags2::TRANSFER_READ.as_raw(),
        ),
        layout: vk::ImageLayout::READ_ONLY_OPTIMAL,
    };
    /// Contents discarded after the stencil's readers are done.
    pub const DISCARD_AFTER_STENCIL_READERS: Use = Use {
        stage: Use::STENCIL_READ_ONLY.stage,
        access: vk::AccessFlags2::NONE,
        layout: vk::ImageLayout::UNDEFINED,
    };
    pub const TRANSFER_DST: Use = Use {
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::COPY.as_raw() | vk::PipelineStageFlags2::CLEAR.as_raw(),
        ),
        access: vk::AccessFlags2::TRANSFER_WRITE,
        layout: vk::ImageLayout::TRANSFER_DST_OPTIMAL,
    };
    pub const TRANSFER_SRC: Use = Use {
        stage: vk::PipelineStageFlags2::COPY,
        access: vk::AccessFlags2::TRANSFER_READ,
        layout: vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
    };
    /// The state every finished pass output is left in.
    pub const READ_ONLY: Use = Use {
        stage: READERS,
        access: READ_ACCESS,
        layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    };
}

pub fn image(image: &Image, from: Use, to: Use) -> vk::ImageMemoryBarrier2<'static> {
    mips(image, 0, image.mips, from, to)
}

/// A barrier for `count` mip levels of `image` starting at `base`.
pub fn mips(
    image: &Image,
    base: u32,
    count: u32,
    from: Use,
    to: Use,
) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(from.stage)
        .src_access_mask(from.access)
        .dst_stage_mask(to.stage)
        .dst_access_mask(to.access)
        .old_layout(from.layout)
        .new_layout(to.layout)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image.image)
        .subresource_range(image.mip_range(base, count))
}

/// Records one `vkCmdPipelineBarrier2` for `barriers`.
pub fn images(gpu: &Gpu, cmd: vk::CommandBuffer, barriers: &[vk::ImageMemoryBarrier2]) {
    if barriers.is_empty() {
        return;
    }
    let dep = vk::DependencyInfo::default().image_memory_barriers(barriers);
    unsafe { gpu.device.cmd_pipeline_barrier2(cmd, &dep) };
}

/// Transitions each image from `from` to `to` in one barrier call.
pub fn transition(gpu: &Gpu, cmd: vk::CommandBuffer, targets: &[&Image], from: Use, to: Use) {
    let barriers: Vec<_> = targets.iter().map(|i| image(i, from, to)).collect();
    images(gpu, cmd, &barriers);
}

/// Clears every mip and layer of a color image to zero (discarding what it
/// held, after its readers) and leaves it in `then`.
pub fn clear_color(gpu: &Gpu, cmd: vk::CommandBuffer, image: &Image, then: Use) {
    transition(
        gpu,
        cmd,
        &[image],
        Use::DISCARD_AFTER_READERS,
        Use::TRANSFER_DST,
    );
    unsafe {
        gpu.device.cmd_clear_color_image(
            cmd,
            image.image,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &vk::ClearColorValue { float32: [0.0; 4] },
            &[image.range()],
        );
    }
    transition(gpu, cmd, &[image], Use::TRANSFER_DST, then);
}

/// Makes one compute dispatch's storage writes visible to the next dispatch.
pub fn compute_to_compute(gpu: &Gpu, cmd: vk::CommandBuffer) {
    let rw = vk::AccessFlags2::from_raw(
        vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
            | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
    );
    memory(
        gpu,
        cmd,
        vk::PipelineStageFlags2::COMPUTE_SHADER,
        vk::AccessFlags2::SHADER_STORAGE_WRITE,
        vk::PipelineStageFlags2::COMPUTE_SHADER,
        rw,
    );
}

/// Makes copies into host-visible buffers readable by the host after the fence.
pub fn copies_to_host(gpu: &Gpu, cmd: vk::CommandBuffer) {
    memory(
        gpu,
        cmd,
        vk::PipelineStageFlags2::COPY,
        vk::AccessFlags2::TRANSFER_WRITE,
        vk::PipelineStageFlags2::HOST,
        vk::AccessFlags2::HOST_READ,
    );
}

/// Zeroes the first `size` bytes of `buffer` (`vk::WHOLE_SIZE`: all of it)
/// once the accesses `after` (stage, access) are done, and makes the zeros
/// visible to the accesses `before`.
pub fn zero_buffer(
    gpu: &Gpu,
    cmd: vk::CommandBuffer,
    buffer: vk::Buffer,
    size: vk::DeviceSize,
    after: (vk::PipelineStageFlags2, vk::AccessFlags2),
    before: (vk::PipelineStageFlags2, vk::AccessFlags2),
) {
    let transfer = vk::PipelineStageFlags2::ALL_TRANSFER;
    let write = vk::AccessFlags2::TRANSFER_WRITE;
    memory(gpu, cmd, after.0, after.1, transfer, write);
    unsafe { gpu.device.cmd_fill_buffer(cmd, buffer, 0, size, 0) };
    memory(gpu, cmd, transfer, write, before.0, before.1);
}

/// A global memory barrier (buffers, host visibility).
pub fn memory(
    gpu: &Gpu,
    cmd: vk::CommandBuffer,
    src_stage: vk::PipelineStageFlags2,
    src_access: vk::AccessFlags2,
    dst_stage: vk::PipelineStageFlags2,
    dst_access: vk::AccessFlags2,
) {
    let barrier = [vk::MemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)];
    let dep = vk::DependencyInfo::default().memory_barriers(&barrier);
    unsafe { gpu.device.cmd_pipeline_barrier2(cmd, &dep) };
}
