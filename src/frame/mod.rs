//! What every pass and method shares, below them all: the settings they were
//! made for, the render targets and samplers, the scene on the GPU, the
//! uniforms, and the frame set (set 0 of every pipeline: this frame's camera,
//! light and instance transforms, and the run's fixed constants).
//!
//! A pass is made once from a [`Setup`] and records each frame into a
//! [`FrameContext`].

pub mod check;
pub mod scene_gpu;
pub mod targets;
pub mod texture_arrays;
pub mod uniforms;

pub use scene_gpu::SceneGpu;
pub use targets::{Samplers, Targets};

use crate::gpu_types::{FrameUniforms, InstanceTransform};
use crate::settings::RenderSettings;
use crate::vk::pipeline::{Binding, DescriptorSet};
use crate::vk::{Buffer, Gpu};
use anyhow::Result;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Frames recorded and submitted ahead of the one being waited for (each
/// has its own frame sets).
pub const FRAMES_IN_FLIGHT: usize = 2;

/// What a pass is made from.
pub struct Setup<'a> {
    pub gpu: &'a Gpu,
    /// A frame set: its layout is set 0 of every pipeline (all frame sets
    /// share one definition).
    pub frame: &'a DescriptorSet,
    pub targets: &'a Targets,
    pub samplers: &'a Samplers,
    pub scene: &'a SceneGpu,
    pub settings: &'a RenderSettings,
    /// The voxel grid's surface sums (`voxel_grid::surface`), where the run
    /// asks for them.
    pub grid_surface: Option<&'a Buffer>,
}

/// What a pass records a frame into.
pub struct FrameContext<'a> {
    pub gpu: &'a Gpu,
    pub cmd: vk::CommandBuffer,
    /// Set 0 of every pipeline in this frame.
    pub frame_set: vk::DescriptorSet,
    pub scene: &'a SceneGpu,
    pub targets: &'a Targets,
}

/// One frame in flight's copy of what changes per frame: the frame uniforms
/// and the instance transforms (host-visible, written before the frame is
/// submitted, after the previous frame that used them has finished), and the
/// frame set that binds them with the run's fixed uniforms and the voxel
/// voxel grid (`voxel_grid`; one grid for every frame set,
/// rebuilt by each frame on the GPU behind a barrier).
pub struct FrameSet {
    pub uniforms: Buffer,
    pub transforms: Buffer,
    pub set: DescriptorSet,
}

impl FrameSet {
    pub fn new(gpu: &Gpu, run: &Buffer, grid: &Buffer, instances: usize) -> Result<Self> {
        let uniforms = Buffer::new(
            gpu,
            "frame uniforms",
            std::mem::size_of::<FrameUniforms>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let transforms = Buffer::new(
            gpu,
            "instance transforms",
            (instances.max(1) * std::mem::size_of::<InstanceTransform>()) as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let set = DescriptorSet::new(
            gpu,
            "frame",
            &[
                Binding::uniform("Frame", &uniforms),
                Binding::uniform("Run", run),
                Binding::storage("Transforms", &transforms),
                Binding::storage("GridOccupancy", grid),
            ],
        )?;
        Ok(Self {
            uniforms,
            transforms,
            set,
        })
    }

    /// Writes a frame's values; call only when no submitted frame reads this set.
    pub fn write(&mut self, uniforms: &FrameUniforms, transforms: &[InstanceTransform]) {
        self.uniforms.write_pod(0, std::slice::from_ref(uniforms));
        self.transforms.write_pod(0, transforms);
    }
}
