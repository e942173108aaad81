//! `cargo bench --bench soak`: 2000 frames of the Cornell box at 64x64 with the
//! light and camera orbiting (and the light's own sweep), for the default
//! method and HISR. Prints resident memory and the GPU allocator's figures
//! after the first frame, after warm-up (frame 100) and at the end; flat
//! figures after warm-up mean nothing leaks per frame.

use isr::scene::cornell::cornell_box;
use isr::settings::RenderSettings;
use isr::soak;
use isr::vk::{Gpu, GpuOptions};

fn main() -> anyhow::Result<()> {
    let frames: u32 = std::env::var("ISR_SOAK_FRAMES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2000);
    let gpu = Gpu::new(&GpuOptions::default())?;
    let scene = cornell_box();
    println!(
        "soak: {frames} frames at 64x64, RSM 128, on {}",
        gpu.info.name
    );
    println!("| method | frame | resident MiB | GPU allocated MiB | GPU blocks MiB (count) |");
    println!("| --- | ---: | ---: | ---: | ---: |");
    for method in [RenderSettings::DEFAULT.method, isr::methods::hisr::KEY] {
        let settings = RenderSettings {
            width: 64,
            height: 64,
            rsm_resolution: 128,
            method,
            ..Default::default()
        }
        .with(&isr::regular_vpls::VPLS, 64);
        let started = std::time::Instant::now();
        let bar = isr::progress::bar(frames as u64, "frames");
        bar.set_message(method.name());
        let samples = soak::run(&gpu, &scene, &settings, frames, 100, |s| {
            bar.set_position(s.frame as u64);
        })?;
        bar.finish_and_clear();
        let mib = |b: u64| b as f64 / (1 << 20) as f64;
        for s in samples
            .iter()
            .filter(|s| s.frame == 1 || s.frame == 100 || s.frame == frames)
        {
            println!(
                "| {} | {} | {:.1} | {:.2} | {:.1} ({}) |",
                method.name(),
                s.frame,
                s.rss_kib as f64 / 1024.0,
                mib(s.gpu_allocated),
                mib(s.gpu_capacity),
                s.gpu_blocks
            );
        }
        let after_warmup: Vec<_> = samples.iter().filter(|s| s.frame >= 100).collect();
        let (lo, hi) = after_warmup.iter().fold((u64::MAX, 0), |(lo, hi), s| {
            (lo.min(s.rss_kib), hi.max(s.rss_kib))
        });
        let gpu_flat = after_warmup.windows(2).all(|w| {
            (w[0].gpu_allocated, w[0].gpu_blocks) == (w[1].gpu_allocated, w[1].gpu_blocks)
        });
        println!(
            "{}: after frame 100, resident memory {:.1}..{:.1} MiB; GPU allocator {}; {:.1} s",
            method.name(),
            lo as f64 / 1024.0,
            hi as f64 / 1024.0,
            if gpu_flat { "unchanged" } else { "CHANGED" },
            started.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
