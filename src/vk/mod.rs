//! Thin layers over ash: device, resources, barriers, uploads, shaders,
//! pipelines, timing.

pub mod barrier;
pub mod context;
pub mod descriptors;
pub mod pipeline;
pub mod profiler;
pub mod reflect;
pub mod resources;
pub mod shaders;
pub mod specialization;
pub mod swapchain;
mod upload;

pub use context::{Gpu, GpuOptions, Validation};
pub use resources::{Buffer, Image, ImageDesc, Sampler};
