//! The runs of `isr render` that are not one GPU frame timed N times: the
//! CPU path tracer and `--sequence`.

use super::*;

/// `--method pathtrace`: the CPU reference, with a progress bar.
pub(super) fn pathtrace(args: &RenderArgs, scene: &scene::Scene) -> Result<()> {
    let run = &args.run;
    if run.width == 0 || run.height == 0 || run.width > 16384 || run.height > 16384 {
        bail!(
            "resolution {}x{}: width and height must be within 1..=16384",
            run.width,
            run.height
        );
    }
    if args.spp == 0 {
        bail!("--spp must be at least 1");
    }
    use crate::settings::params::AnyParam as _;
    let bounces = &crate::bounces::BOUNCES;
    let settings = crate::settings::RenderSettings {
        params: run.params.0.clone(),
        ..crate::settings::RenderSettings::DEFAULT
    };
    bounces.check(&settings)?;
    let bounces = bounces.get(&settings);
    let threads = rayon::current_num_threads();
    eprintln!(
        "path tracing {} ({} triangles) at {}x{}, {} spp, {}, on {threads} CPU threads",
        scene.name,
        scene.triangle_count(),
        run.width,
        run.height,
        args.spp,
        bounces.words()
    );
    let started = std::time::Instant::now();
    let bar = crate::progress::bar(run.height as u64, "rows");
    let result = crate::pathtrace::render(
        scene,
        &crate::pathtrace::PathTraceSettings {
            width: run.width,
            height: run.height,
            spp: args.spp,
            seed: args.seed,
            exposure: run.exposure,
            bounces,
        },
        |done, _rows| bar.set_position(done as u64),
    );
    bar.finish_and_clear();
    let ms = started.elapsed().as_secs_f64() * 1e3;
    println!("pathtrace: {ms:.1} ms on {threads} CPU threads");
    if let Some(path) = &args.timings {
        let r = report::TimingReport {
            device: format!("CPU ({threads} threads)"),
            driver: "isr::pathtrace".into(),
            scene: scene.name.clone(),
            width: run.width,
            height: run.height,
            rsm: 0,
            method: crate::pathtrace::NAME.into(),
            frames: 1,
            passes: vec![],
            total_gpu_ms_median: None,
            indirect_gpu_ms_median: None,
            wall_ms_median: ms,
            patches_per_level: None,
            light_patches: None,
            time: None,
        };
        report::write_json(path, &r)?;
        println!("wrote {}", path.display());
    }
    output::write_exr(&args.out, &result)?;
    output::write_png(&args.png, result.width, result.height, &result.display)?;
    println!("wrote {} and {}", args.out.display(), args.png.display());
    Ok(())
}

/// The most memory `--gif` may hold in frames (RGBA8).
const MAX_GIF_BYTES: u64 = 2 << 30;

/// `--sequence DIR`: frame k at time `--time + k / --fps`, each written as
/// EXR and PNG, and every frame's per-pass times in `DIR/timings.json`.
pub(super) fn sequence(
    args: &RenderArgs,
    scene: &scene::Scene,
    gpu: &Gpu,
    renderer: &mut Renderer,
    dir: &std::path::Path,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let (width, height) = (args.run.width, args.run.height);
    let mut reports = Vec::new();
    let mut gif_frames = Vec::new();
    if args.gif {
        // The frames are kept for the GIF: refuse a length that cannot fit.
        let bytes = args.frames as u64 * width as u64 * height as u64 * 4;
        if bytes > MAX_GIF_BYTES {
            bail!(
                "--gif: {} frames of {}x{} need {} MiB in memory (the limit is {} MiB); \
                 render fewer or smaller frames",
                args.frames,
                width,
                height,
                bytes >> 20,
                MAX_GIF_BYTES >> 20
            );
        }
    }
    let bar = crate::progress::bar(args.frames as u64, "frames");
    // What an interruption leaves (`interrupt`): the frames before the one
    // in progress, and no timings.json or GIF of this run.
    super::interrupt::set_note(format!(
        "no frame in {} is complete; timings.json was not written",
        dir.display()
    ));
    for k in 0..args.frames {
        let t = args.run.time + k as f32 / args.fps;
        renderer.update(&args.state_at(scene, t)?)?;
        // Each frame is its own run of one frame: its images are read back
        // and written before the next one changes the scene. Whatever of it
        // fails (the frame, its readback, its files) names what is kept.
        let exr = dir.join(format!("frame_{k:04}.exr"));
        let png = dir.join(format!("frame_{k:04}.png"));
        let frame = (|| -> Result<(crate::renderer::FrameStats, Vec<u8>)> {
            let stats = renderer.render_frames(1, |_| {})?;
            let result = renderer.readback()?;
            output::write_exr(&exr, &result)?;
            output::write_png(&png, result.width, result.height, &result.display)?;
            Ok((stats, result.display))
        })();
        let (stats, display) = frame.map_err(|e| {
            bar.abandon();
            e.context(format!(
                "rendering frame {k} (t = {t} s) failed; {}timings.json was not written",
                if k > 0 {
                    format!(
                        "frames 0000 to {:04} in {} are complete, ",
                        k - 1,
                        dir.display()
                    )
                } else {
                    String::new()
                }
            ))
        })?;
        super::interrupt::set_note(format!(
            "{} in {} complete; timings.json was not written",
            match k {
                0 => "frame 0000 is".to_string(),
                _ => format!("frames 0000 to {k:04} are"),
            },
            dir.display()
        ));
        if args.gif {
            gif_frames.push(display);
        }
        let mut r = args.report(gpu, scene, &stats);
        r.time = Some(t);
        reports.push(r);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let path = dir.join("timings.json");
    let text = serde_json::to_string_pretty(&serde_json::json!({ "frames": reports }))?;
    output::write_text(&path, &text)?;
    super::interrupt::set_note(format!(
        "every frame and timings.json in {} are complete{}",
        dir.display(),
        if args.gif {
            "; sequence.gif was not written"
        } else {
            ""
        }
    ));
    println!(
        "wrote {} frames ({}/frame_0000.exr ...) and {}",
        args.frames,
        dir.display(),
        path.display()
    );
    if args.gif {
        let gif = dir.join("sequence.gif");
        output::write_gif(&gif, width, height, gif_frames, args.fps)?;
        println!("wrote {}", gif.display());
    }
    gpu.validation_verdict()
}
