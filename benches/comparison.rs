//! `cargo bench --bench comparison`: every method on the same RSM, scene and
//! composite (the built-in Cornell box, 256x256, RSM 256, 256 VPLs where a
//! method takes N), against the converged `reference` (all 65,536 RSM texels
//! at full resolution), plus the path tracer (256 spp) to show what ignoring
//! indirect visibility costs (every method without `--visibility` and with
//! one bounce, as the paper's). Prints indirect GPU time and the relative RMSE of the indirect
//! and final images; writes `target/bench/comparison.json`, one PNG per
//! method to `target/bench/comparison/`, and the README's picture of the box
//! by nine methods, `assets/comparison.png` ([`MONTAGE`], in reading order).

use isr::bench::metrics::{geometry_mask, relative_rmse};
use isr::readback::Readback;
use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::{Method, RenderSettings};
use isr::vk::{Gpu, GpuOptions};
use serde_json::json;

/// The README's picture: three rows of three, in reading order.
const MONTAGE: [&str; 9] = [
    "hisr",
    "isr",
    "multires-gather",
    "rsm-gather",
    "rsm-splat",
    "lpv",
    "vct",
    "reference",
    "pathtrace",
];

/// Writes the [`MONTAGE`] of `images` (method name, RGBA8 of `side` x
/// `side`) to `path`, with a 4-pixel white gutter.
fn montage(path: &std::path::Path, side: u32, images: &[(String, Vec<u8>)]) -> anyhow::Result<()> {
    let gutter = 4;
    let w = 3 * side + 2 * gutter;
    let mut out = vec![255u8; (w * w * 4) as usize];
    for (k, name) in MONTAGE.iter().enumerate() {
        let Some((_, px)) = images.iter().find(|(n, _)| n == name) else {
            anyhow::bail!("the montage needs {name}, which did not render");
        };
        let (x0, y0) = (
            (k as u32 % 3) * (side + gutter),
            (k as u32 / 3) * (side + gutter),
        );
        for y in 0..side {
            let src = (y * side * 4) as usize;
            let dst = (((y0 + y) * w + x0) * 4) as usize;
            out[dst..dst + (side * 4) as usize]
                .copy_from_slice(&px[src..src + (side * 4) as usize]);
        }
    }
    isr::output::write_png(path, w, w, &out)
}

fn main() -> anyhow::Result<()> {
    let gpu = Gpu::new(&GpuOptions::default())?;
    let scene = cornell_box();
    let base = RenderSettings {
        width: 256,
        height: 256,
        rsm_resolution: 256,
        ..Default::default()
    }
    .with(
        &isr::visibility::VISIBILITY,
        isr::visibility::Visibility::None,
    )
    // One bounce, the paper's model, which every method here renders
    // (`lpv` and `vct` have no further bounces).
    .with(&isr::bounces::BOUNCES, isr::bounces::Bounces::ONE);
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench/comparison");
    std::fs::create_dir_all(&dir)?;
    let run = |method: Method, frames: u32| -> anyhow::Result<(Readback, f64)> {
        let s = RenderSettings {
            method,
            ..base.clone()
        };
        let mut r = Renderer::new(&gpu, &scene, &s)?;
        let stats = r.render_frames(frames, |_| {})?;
        let out = r.readback()?;
        isr::output::write_png(
            &dir.join(format!("{}.png", method.name())),
            out.width,
            out.height,
            &out.display,
        )?;
        eprintln!("{}: done", method.name());
        Ok((out, stats.gpu_ms_median(true).unwrap_or(f64::NAN)))
    };
    let (reference, reference_ms) = run(isr::methods::reference::KEY, 1)?;
    let traced = isr::pathtrace::render(
        &scene,
        &isr::pathtrace::PathTraceSettings {
            width: 256,
            height: 256,
            spp: 256,
            seed: 1,
            exposure: 1.0,
            bounces: isr::bounces::Bounces::ONE,
        },
        |_, _| {},
    );
    isr::output::write_png(&dir.join("pathtrace.png"), 256, 256, &traced.display)?;
    let mut images = vec![
        ("reference".to_owned(), reference.display.clone()),
        ("pathtrace".to_owned(), traced.display.clone()),
    ];
    // The methods `isr bench` sweeps, at their defaults.
    let methods = isr::bench::sweep::methods();
    let mut rows = Vec::new();
    println!(
        "{:<22} {:>12} {:>16} {:>14}",
        "method", "indirect ms", "indirect RMSE", "final RMSE"
    );
    let geometry = &geometry_mask(&reference.position);
    for m in methods {
        let (out, ms) = run(m, 3)?;
        images.push((m.name().to_owned(), out.display.clone()));
        let ei = relative_rmse(&out.indirect, &reference.indirect, geometry);
        let ef = relative_rmse(&out.final_radiance, &reference.final_radiance, geometry);
        println!("{:<22} {:>12.1} {:>16.4} {:>14.4}", m.name(), ms, ei, ef);
        rows.push(
            json!({"method": m.name(), "indirect_ms": ms, "indirect_rmse": ei, "final_rmse": ef}),
        );
    }
    let ei = relative_rmse(&traced.indirect, &reference.indirect, geometry);
    let ef = relative_rmse(&traced.final_radiance, &reference.final_radiance, geometry);
    println!(
        "{:<22} {:>12} {:>16.4} {:>14.4}",
        "pathtrace (256 spp)", "cpu", ei, ef
    );
    println!("reference: {reference_ms:.1} ms indirect");
    montage(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/comparison.png"),
        256,
        &images,
    )?;
    rows.push(json!({"method": "pathtrace", "indirect_rmse": ei, "final_rmse": ef}));
    std::fs::write(
        dir.join("../comparison.json"),
        serde_json::to_string_pretty(
            &json!({"device": gpu.info.name, "width": 256, "height": 256, "rsm": 256, "vpls": isr::regular_vpls::VPLS.get(&base),
            "reference_ms": reference_ms, "runs": rows}),
        )?,
    )?;
    Ok(())
}
