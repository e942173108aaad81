//! `cargo bench --bench light_space`: indirect time and error of HISR, Basic
//! ISR and multires-gather with 256, 1024 and 4096 VPLs, measured in one run
//! on the built-in Cornell box at 512x512 with a 256x256 RSM. The reference is
//! the dense gather of every RSM texel (65,536 VPLs) through the same
//! eye-space patches, so the error is the light-space choice alone.
//! Writes `target/bench/light_space.json`.

use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::{LightTreeSettings, Method, RenderSettings};
use isr::vk::{Gpu, GpuOptions};
use serde_json::json;

struct Run {
    label: String,
    indirect_ms: f64,
    patches_per_eye_patch: f64,
    indirect: Vec<[f32; 4]>,
}

fn run(gpu: &Gpu, label: &str, s: &RenderSettings, frames: u32) -> anyhow::Result<Run> {
    let scene = cornell_box();
    let mut r = Renderer::new(gpu, &scene, s)?;
    r.render_frames(1, |_| {})?;
    let stats = r.render_frames(frames, |_| {})?;
    let m = r.readback_multires()?.unwrap();
    let light = isr::debug_view::light_patch_stats(&m, None);
    let indirect = r.readback()?.indirect;
    eprintln!("{label}: done");
    Ok(Run {
        label: label.into(),
        indirect_ms: stats.gpu_ms_median(true).unwrap_or(f64::NAN),
        patches_per_eye_patch: light.per_patch_mean,
        indirect,
    })
}

fn main() -> anyhow::Result<()> {
    let gpu = Gpu::new(&GpuOptions::default())?;
    // ISR_BENCH_SIZE=256 for a quicker run.
    let size: u32 = std::env::var("ISR_BENCH_SIZE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(512);
    let base = RenderSettings {
        width: size,
        height: size,
        rsm_resolution: 256,
        ..Default::default()
    };
    let with = |method, vpls, lt: LightTreeSettings| RenderSettings {
        method,
        vpls,
        light_tree: lt,
        ..base.clone()
    };
    let reference = run(
        &gpu,
        "dense (65536 VPLs)",
        &with(Method::MultiresGather, 65536, Default::default()),
        1,
    )?;
    let mut runs = Vec::new();
    for n in [256, 1024, 4096] {
        runs.push(run(
            &gpu,
            &format!("multires-gather {n}"),
            &with(Method::MultiresGather, n, Default::default()),
            3,
        )?);
    }
    runs.push(run(
        &gpu,
        "isr (base 64)",
        &with(Method::Isr, 256, Default::default()),
        3,
    )?);
    for tau in [0.5, 0.2, 0.05, 0.01] {
        let lt = LightTreeSettings {
            tau,
            ..Default::default()
        };
        runs.push(run(
            &gpu,
            &format!("hisr tau {tau}"),
            &with(Method::Hisr, 256, lt),
            2,
        )?);
    }
    let mut rows = Vec::new();
    println!(
        "{:<22} {:>12} {:>18} {:>14}",
        "method", "indirect ms", "patches/eye patch", "rel. RMSE"
    );
    for r in &runs {
        let (mut err, mut norm) = (0.0f64, 0.0f64);
        for (a, b) in r.indirect.iter().zip(&reference.indirect) {
            for k in 0..3 {
                err += (a[k] as f64 - b[k] as f64).powi(2);
                norm += (b[k] as f64).powi(2);
            }
        }
        let rmse = (err / norm).sqrt();
        println!(
            "{:<22} {:>12.1} {:>18.1} {:>14.4}",
            r.label, r.indirect_ms, r.patches_per_eye_patch, rmse
        );
        rows.push(json!({"method": r.label, "indirect_ms": r.indirect_ms, "patches_per_eye_patch": r.patches_per_eye_patch, "relative_rmse": rmse}));
    }
    println!("reference: {} ms indirect", reference.indirect_ms);
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(
        dir.join("light_space.json"),
        serde_json::to_string_pretty(
            &json!({"device": gpu.info.name, "width": size, "height": size, "rsm": 256, "runs": rows}),
        )?,
    )?;
    Ok(())
}
