//! Cost against scene size (issue 27): for every bench scene, from the
//! 20-triangle `moving-block` to the 331k-triangle conference room, the load
//! time, what the GPU allocator holds, each pass's median time for a few
//! methods, and the path tracer's BVH build and trace times. Prints one
//! markdown table per measure.
//!
//!     cargo run --release --example scene_costs [-- SIZE RSM FRAMES]
//!
//! SIZE x SIZE pixels (default 128), RSM (default 128), FRAMES frames timed
//! per method (default 5); the path tracer at PT x PT pixels, SPP samples
//! per pixel (defaults 64 and 16: its progress reporter wakes every 250 ms,
//! so a render of less than a second is timed to within that).
//! The archive scenes need the archive folder (ISR_SCENES).

use isr::bench::scenes;
use isr::pathtrace::bvh::{Bvh, Triangle};
use isr::renderer::Renderer;
use isr::settings::{Method, RenderSettings};
use isr::vk::{Gpu, GpuOptions};
use std::time::Instant;

const METHODS: &[&str] = &["none", "rsm-gather", "multires-gather", "isr", "hisr"];

fn allocated(gpu: &Gpu) -> u64 {
    gpu.shared
        .allocator
        .lock()
        .map(|a| a.generate_report().total_allocated_bytes)
        .unwrap_or(0)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let size = args.first().copied().unwrap_or(128);
    let rsm = args.get(1).copied().unwrap_or(128);
    let frames = args.get(2).copied().unwrap_or(5);
    let pt = args.get(3).copied().unwrap_or(64);
    let spp = args.get(4).copied().unwrap_or(16);
    let gpu = Gpu::new(&GpuOptions::default())?;
    println!("device: {} ({}); {size}x{size}, RSM {rsm}, {frames} frames (medians of all but the counting one)\n", gpu.info.name, gpu.info.driver);
    let names: Vec<&str> = scenes::SCENES
        .iter()
        .chain(scenes::ARCHIVE)
        .map(|s| s.name)
        .collect();
    let mut rows = vec![];
    for name in names {
        let started = Instant::now();
        let scene = scenes::build(name)?;
        let load_ms = started.elapsed().as_secs_f64() * 1e3;
        let state = scene.pose_at(0.1)?;
        let triangles = scene.triangle_count();
        let vertices: usize = scene.meshes.iter().map(|m| m.vertices.len()).sum();
        let mut per_method = vec![];
        let mut memory = vec![];
        for &m in METHODS {
            let settings = RenderSettings {
                width: size,
                height: size,
                rsm_resolution: rsm,
                method: Method::new(m),
                ..RenderSettings::DEFAULT
            };
            let before = allocated(&gpu);
            let t = Instant::now();
            let mut r = Renderer::new(&gpu, &scene, &settings)?;
            let setup_ms = t.elapsed().as_secs_f64() * 1e3;
            memory.push(allocated(&gpu) - before);
            r.update(&state)?;
            let stats = r.render_frames(frames, |_| {})?;
            let report = isr::report::build(
                &isr::report::RunInfo {
                    device: "",
                    driver: "",
                    scene: name,
                    width: size,
                    height: size,
                    rsm,
                    method: m,
                },
                &stats,
            );
            per_method.push((m, setup_ms, report));
        }
        // The path tracer: its BVH built alone, then a whole render.
        let mut posed = scene.clone();
        posed.camera = state.camera;
        posed.lights = state.lights.clone();
        for (inst, m) in posed.instances.iter_mut().zip(&state.instance_transforms) {
            inst.world_from_object = *m;
        }
        let mut tris = vec![];
        for inst in &posed.instances {
            let mesh = &posed.meshes[inst.mesh];
            for t in mesh.indices.chunks_exact(3) {
                let p =
                    |k: usize| {
                        glam::Vec3A::from(inst.world_from_object.transform_point3(
                            glam::Vec3::from(mesh.vertices[t[k] as usize].position),
                        ))
                    };
                tris.push(Triangle {
                    p: [p(0), p(1), p(2)],
                    n: [glam::Vec3A::Y; 3],
                    uv: [[0.0; 2]; 3],
                    material: 0,
                    double_sided: true,
                });
            }
        }
        let t = Instant::now();
        let bvh = Bvh::new(tris);
        let bvh_ms = t.elapsed().as_secs_f64() * 1e3;
        drop(bvh);
        let t = Instant::now();
        let _ = isr::pathtrace::render(
            &posed,
            &isr::pathtrace::PathTraceSettings {
                width: pt,
                height: pt,
                spp,
                seed: 1,
                exposure: 1.0,
                bounces: isr::bounces::Bounces::ONE,
            },
            |_, _| {},
        );
        let pathtrace_ms = t.elapsed().as_secs_f64() * 1e3;
        eprintln!("{name}: {triangles} triangles measured");
        rows.push((
            name,
            triangles,
            vertices,
            load_ms,
            memory,
            per_method,
            bvh_ms,
            pathtrace_ms,
        ));
    }
    println!("## Load, memory, path tracer\n");
    println!("| scene | triangles | vertices | load ms | GPU MiB (none) | GPU MiB (hisr) | BVH build ms | pathtrace {pt}x{pt}, {spp} spp, ms (build included) |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (name, tri, vert, load, mem, _, bvh, pt) in &rows {
        let mib = |b: u64| b as f64 / (1 << 20) as f64;
        println!(
            "| {name} | {tri} | {vert} | {load:.1} | {:.1} | {:.1} | {bvh:.1} | {pt:.0} |",
            mib(mem[0]),
            mib(mem[METHODS.len() - 1])
        );
    }
    for (k, &m) in METHODS.iter().enumerate() {
        println!("\n## {m}: median ms per pass\n");
        let mut passes: Vec<String> = vec![];
        for r in &rows {
            for p in &r.5[k].2.passes {
                if !passes.contains(&p.name) {
                    passes.push(p.name.clone());
                }
            }
        }
        println!(
            "| scene | triangles | setup ms | {} | indirect | total |",
            passes.join(" | ")
        );
        println!(
            "| --- | ---: | ---: |{} ---: | ---: |",
            " ---: |".repeat(passes.len())
        );
        for r in &rows {
            let (_, setup, report) = &r.5[k];
            let cells: Vec<String> = passes
                .iter()
                .map(|name| {
                    report
                        .passes
                        .iter()
                        .find(|p| &p.name == name)
                        .and_then(|p| p.gpu_ms_median)
                        .map_or("-".into(), |v| format!("{v:.2}"))
                })
                .collect();
            println!(
                "| {} | {} | {setup:.0} | {} | {} | {} |",
                r.0,
                r.1,
                cells.join(" | "),
                report
                    .indirect_gpu_ms_median
                    .map_or("-".into(), |v| format!("{v:.2}")),
                report
                    .total_gpu_ms_median
                    .map_or("-".into(), |v| format!("{v:.2}"))
            );
        }
    }
    Ok(())
}
