//! `isr`: one bounce of diffuse indirect light from reflective shadow maps,
//! with image-space hierarchies in eye space and light space (Nichols, Shopf,
//! Wyman, EGSR 2009), and the methods it was measured against.
//!
//! Reading order: `renderer` (one frame), `passes` (one module per pass),
//! `vk` (device, resources, barriers, pipelines, timing), `scene`.

pub mod cli;
pub mod debug_view;
pub mod gpu_types;
pub mod methods;
pub mod multires;
pub mod output;
pub mod passes;
pub mod pathtrace;
pub mod renderer;
pub mod report;
pub mod scene;
pub mod vk;
