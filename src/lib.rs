//! `isr`: one bounce of diffuse indirect light from reflective shadow maps,
//! with image-space hierarchies in eye space and light space (Nichols, Shopf,
//! Wyman, EGSR 2009), and the methods it was measured against.
//!
//! Reading order: `renderer` (creates, records, submits), `frame` (what every
//! pass shares), `passes` (one module per shared pass), `methods` (one module
//! per indirect method, and their registry), `multires` (the eye-space
//! framework), `voxel_grid` and `visibility`, `vk` (device, resources,
//! barriers, pipelines, timing), `scene`. docs/architecture.md has the map.

pub mod bench;
pub mod bounces;
pub mod cli;
pub mod debug_view;
pub mod exact_visibility;
pub mod frame;
pub mod gpu_types;
pub mod method_args;
pub mod methods;
pub mod multires;
pub mod output;
pub mod passes;
pub mod pathtrace;
pub mod placement;
pub mod progress;
pub mod readback;
pub mod regular_vpls;
pub mod renderer;
pub mod report;
pub mod scene;
pub mod settings;
pub mod soak;
pub mod view;
pub mod viewer;
pub mod visibility;
pub mod vk;
pub mod voxel_grid;
