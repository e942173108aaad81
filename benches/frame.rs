//! `cargo bench`: per-pass GPU times of the built-in Cornell box at a few
//! resolutions, as medians over 20 frames, written to `target/bench/`.
//! Speed targets live here, not in tests. On lavapipe absolute times mean
//! little; compare passes and methods measured in the same run.

use isr::renderer::Renderer;
use isr::report;
use isr::scene::cornell::cornell_box;
use isr::settings::RenderSettings;
use isr::vk::{Gpu, GpuOptions};

fn main() -> anyhow::Result<()> {
    let gpu = Gpu::new(&GpuOptions::default())?;
    let scene = cornell_box();
    let out_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench");
    std::fs::create_dir_all(&out_dir)?;
    for size in [256u32, 512, 1024] {
        let settings = RenderSettings {
            width: size,
            height: size,
            rsm_resolution: 512,
            ..Default::default()
        };
        let mut r = Renderer::new(&gpu, &scene, &settings)?;
        r.render_frames(3, |_| {})?; // warm-up
        let stats = r.render_frames(20, |_| {})?;
        let rep = report::build(
            &report::RunInfo {
                device: &gpu.info.name,
                driver: &gpu.info.driver,
                scene: &scene.name,
                width: size,
                height: size,
                rsm: settings.rsm_resolution,
                method: settings.method.name(),
            },
            &stats,
        );
        println!("{}", report::table(&rep));
        std::fs::write(
            out_dir.join(format!("frame-{size}.json")),
            serde_json::to_string_pretty(&rep)?,
        )?;
    }
    Ok(())
}
