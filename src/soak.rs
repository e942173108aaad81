//! Soak: many frames with the light and the camera moving, sampling the
//! process's resident memory and the GPU allocator's report as they go. A
//! leak per frame (host or GPU) shows as growth after the warm-up.
//! `benches/soak.rs` reports the figures; `tests/soak.rs` holds them flat.

use crate::renderer::Renderer;
use crate::scene::{motion, Scene};
use crate::settings::RenderSettings;
use crate::vk::Gpu;
use anyhow::Result;

/// The figures at one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SoakSample {
    /// Frames rendered so far.
    pub frame: u32,
    /// Resident set size of the process (KiB), from /proc/self/status; 0
    /// where the system has none.
    pub rss_kib: u64,
    /// Bytes the GPU allocator has handed out, and the blocks it holds.
    pub gpu_allocated: u64,
    pub gpu_capacity: u64,
    pub gpu_blocks: usize,
}

/// Resident memory of this process in KiB (0 where /proc is missing).
pub fn resident_kib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmRSS:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        })
        .unwrap_or(0)
}

fn sample(gpu: &Gpu, frame: u32) -> SoakSample {
    let report = gpu.shared.allocator.lock().unwrap().generate_report();
    SoakSample {
        frame,
        rss_kib: resident_kib(),
        gpu_allocated: report.total_allocated_bytes,
        gpu_capacity: report.total_capacity_bytes,
        gpu_blocks: report.blocks.len(),
    }
}

/// Renders `frames` frames of `scene` at 30 frames per second of animation
/// time, the light and the camera orbiting (periods 3 s and 5 s) on top of
/// the scene's own animation, one frame per update as a viewer would; samples
/// every `every` frames (and after the first and the last).
pub fn run(
    gpu: &Gpu,
    scene: &Scene,
    settings: &RenderSettings,
    frames: u32,
    every: u32,
    mut progress: impl FnMut(&SoakSample),
) -> Result<Vec<SoakSample>> {
    let mut r = Renderer::new(gpu, scene, settings)?;
    let pivot = motion::pivot(scene);
    let mut samples = Vec::new();
    for k in 0..frames {
        let t = k as f32 / 30.0;
        let mut state = scene.pose_at(t)?;
        motion::orbit_light(&mut state, pivot, 3.0, t);
        motion::orbit_camera(&mut state, pivot, 5.0, t);
        r.update(&state)?;
        r.render_frames(1, |_| {})?;
        let done = k + 1;
        if done == 1 || done % every.max(1) == 0 || done == frames {
            let s = sample(gpu, done);
            progress(&s);
            samples.push(s);
        }
    }
    Ok(samples)
}
