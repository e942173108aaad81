//! Thin layers over ash: device, resources, barriers, pipelines, timing.

pub mod barrier;
pub mod context;
pub mod descriptors;
pub mod pipeline;
pub mod profiler;
pub mod reflect;
pub mod resources;
pub mod swapchain;

pub use context::{Gpu, GpuOptions, Validation};
pub use resources::{Buffer, Image, ImageDesc, Sampler};
