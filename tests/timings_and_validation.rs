//! Per-pass timings and the validation layer over several frames.
mod common;

use common::cli::Isr;
use common::*;
use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::{Method, RenderSettings};

const PASSES: [&str; 6] = ["rsm", "gbuffer", "shadow", "direct", "composite", "tonemap"];

#[test]
fn every_pass_is_timed_and_the_sum_fits_in_the_frame_wall_time() {
    let gpu = gpu();
    let settings = sized("none", 128, 128, 128);
    let out = render(&gpu, &cornell_box(), &settings, 4);
    assert_eq!(out.stats.frames.len(), 4);
    // The last frame counts; the three before it only time.
    assert_eq!(out.stats.counted, [false, false, false, true]);
    assert_eq!(out.stats.timed().count(), 3);
    let frames = out.stats.frames.iter().zip(&out.stats.counted);
    for ((frame, &counted), wall) in frames.zip(&out.stats.wall_ms) {
        let names: Vec<&str> = frame.iter().map(|p| p.name).collect();
        assert_eq!(names, PASSES);
        let mut sum = 0.0;
        for p in frame {
            let ms = p.gpu_ms.expect("lavapipe supports timestamps");
            // Every pass does work at 128x128; a zero would mean a missing timestamp.
            assert!(ms > 0.0, "pass {} took {ms} ms", p.name);
            sum += ms;
            assert_eq!(
                p.fragment_invocations.is_some_and(|n| n > 0),
                counted,
                "pass {}: a fragment count only in the counting frame",
                p.name
            );
            assert_eq!(
                p.samples_passed.is_some_and(|n| n > 0),
                counted,
                "pass {}: samples passed only in the counting frame",
                p.name
            );
        }
        assert!(
            sum <= *wall,
            "passes sum to {sum} ms but the frame took {wall} ms of wall time"
        );
    }
    // Full-screen passes shade every pixel exactly once.
    let last = out.stats.counts().unwrap();
    for p in last
        .iter()
        .filter(|p| ["direct", "composite", "tonemap"].contains(&p.name))
    {
        assert_eq!(p.samples_passed, Some(128 * 128), "pass {}", p.name);
    }
}

#[test]
fn patches_are_counted_only_in_a_counting_frame_and_match_the_gathered_texels() {
    let gpu = gpu();
    let settings = sized("multires-gather", 128, 128, 128);
    let mut r = Renderer::new(&gpu, &cornell_box(), &settings).expect("renderer setup");
    // Frames that only time skip the stencil pass's atomics: no counts.
    let timed = r.render_frames_counting(3, false, |_| {}).unwrap();
    assert_eq!(timed.counted, [false; 3]);
    assert_eq!(timed.patches_per_level, None);
    let counted = r.render_frames(1, |_| {}).unwrap();
    let patches = counted.patches_per_level.clone();
    let patches = patches.expect("a counting frame counts patches");
    // The stencil pass counts the texels the gather's stencil test passes.
    let gather = counted
        .counts()
        .unwrap()
        .iter()
        .find(|p| p.name == "gather");
    let passed = gather.and_then(|p| p.samples_passed).unwrap();
    assert!(passed > 0);
    // Exact only with precise occlusion queries (else any non-zero count).
    if gpu.features.precise_occlusion {
        assert_eq!(patches.iter().map(|&n| n as u64).sum::<u64>(), passed);
    }
    drop(r);
    assert_validation_clean(&gpu);
}

#[test]
fn one_frames_indirect_time_is_the_sum_of_its_passes() {
    use isr::report::{build, RunInfo};
    let gpu = gpu();
    let out = render(
        &gpu,
        &cornell_box(),
        &sized("multires-gather", 96, 64, 64),
        4,
    );
    let info = RunInfo {
        device: "",
        driver: "",
        scene: "",
        width: 96,
        height: 64,
        rsm: 64,
        method: "multires-gather",
    };
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs());
    let mut sums = vec![];
    for frame in out.stats.timed() {
        let passes = |indirect: bool| {
            frame
                .iter()
                .filter(move |p| p.kind.indirect || !indirect)
                .map(|p| p.gpu_ms.expect("timestamps"))
        };
        let (indirect, total): (f64, f64) = (passes(true).sum(), passes(false).sum());
        assert!(
            indirect > 0.0 && indirect < total,
            "{indirect} of {total} ms"
        );
        // The report of this frame alone: its indirect time is the sum of
        // its indirect passes' times, as listed in the same report.
        let one = isr::renderer::FrameStats {
            frames: vec![frame.clone()],
            counted: vec![false],
            wall_ms: vec![0.0],
            ..Default::default()
        };
        let r = build(&info, &one);
        let listed: f64 = r
            .passes
            .iter()
            .filter(|p| p.indirect)
            .map(|p| p.gpu_ms_median.unwrap())
            .sum();
        let reported = r.indirect_gpu_ms_median.unwrap();
        assert!(
            close(reported, indirect) && close(reported, listed),
            "one frame: indirect {reported} ms reported, its passes sum to {indirect} (listed: {listed})"
        );
        assert!(close(r.total_gpu_ms_median.unwrap(), total));
        sums.push(indirect);
    }
    // Three timed frames: the report's indirect median is the middle sum.
    assert_eq!(sums.len(), 3);
    sums.sort_by(f64::total_cmp);
    let r = build(&info, &out.stats);
    assert!(
        close(r.indirect_gpu_ms_median.unwrap(), sums[1]),
        "{:?} vs the frames' indirect sums {sums:?}",
        r.indirect_gpu_ms_median
    );
}

#[test]
fn timings_json_from_the_cli_lists_every_pass() {
    let dir = temp_dir("timings");
    let ran = Isr::render(&dir)
        .args([
            "--width", "96", "--height", "64", "--rsm", "64", "--frames", "3",
        ])
        .args(["--timings", "t.json", "--out", "r.exr", "--png", "r.png"])
        .succeeds();
    let json = dir.join("t.json");
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    for key in [
        "device",
        "driver",
        "width",
        "height",
        "method",
        "frames",
        "passes",
        "total_gpu_ms_median",
        "indirect_gpu_ms_median",
    ] {
        assert!(v.get(key).is_some(), "timings JSON lacks {key}: {v}");
    }
    assert_eq!(v["width"], 96);
    assert_eq!(v["frames"], 3);
    let passes = v["passes"].as_array().unwrap();
    let names: Vec<&str> = passes.iter().map(|p| p["name"].as_str().unwrap()).collect();
    // The default method, HISR with the voxel grid and every bounce, adds
    // its indirect passes: the grid and the surface in its cells after the
    // G-buffer (they need only the posed scene), the rest between direct
    // light and the composite, the bounces last.
    let indirect = [
        "voxel-grid",
        "voxel-surface",
        "rsm-tree",
        "geometry-mips",
        "stencil-refine",
        "light-tree-pack",
        "hisr-cut",
        "hisr-visibility",
        "gather",
        "upsample",
        "bounce-cells",
        "bounce-transfer",
        "bounce-propagate",
        "bounce-gather",
        "bounce-add",
    ];
    let expected: Vec<&str> = PASSES[..2]
        .iter()
        .chain(&indirect[..2])
        .chain(&PASSES[2..4])
        .chain(&indirect[2..])
        .chain(&PASSES[4..])
        .copied()
        .collect();
    assert_eq!(names, expected);
    let mut indirect_min_sum = 0.0;
    for p in passes {
        let is_indirect = indirect.contains(&p["name"].as_str().unwrap());
        assert_eq!(p["indirect"].as_bool(), Some(is_indirect), "{p}");
        if is_indirect {
            indirect_min_sum += p["gpu_ms_min"].as_f64().unwrap();
        }
    }
    let indirect_median = v["indirect_gpu_ms_median"].as_f64().unwrap();
    assert!(indirect_median > 0.0 && indirect_median <= v["total_gpu_ms_median"].as_f64().unwrap());
    // The median of the frames' indirect sums is one frame's sum, which is
    // at least the sum of each indirect pass's least time (exactly, up to
    // float rounding; `one_frames_indirect_time_is_the_sum_of_its_passes`
    // checks the sums themselves).
    assert!(
        indirect_min_sum <= indirect_median * (1.0 + 1e-12),
        "indirect median {indirect_median} ms below the sum of the passes' least times {indirect_min_sum}"
    );
    let patches = v["patches_per_level"]
        .as_array()
        .expect("patch counts in the JSON");
    assert!(patches.iter().map(|c| c.as_u64().unwrap()).sum::<u64>() > 0);
    let mut sum = 0.0;
    for p in passes {
        let med = p["gpu_ms_median"].as_f64().unwrap();
        let min = p["gpu_ms_min"].as_f64().unwrap();
        assert!(min >= 0.0 && min <= med, "{p}");
        assert!(p["fragment_invocations"].as_u64().is_some(), "{p}");
        sum += med;
    }
    assert!(sum > 0.0);

    let table = &ran.stdout;
    for name in expected {
        assert!(
            table.contains(name),
            "the printed table lacks {name}:\n{table}"
        );
    }
    assert!(std::fs::metadata(dir.join("r.exr")).unwrap().len() > 0);
    let png = image::open(dir.join("r.png")).unwrap();
    assert_eq!((png.width(), png.height()), (96, 64));
}

#[test]
fn validation_with_synchronization_checks_is_silent_over_several_frames() {
    let gpu = validating_gpu();
    assert!(gpu.validating());
    // Every registered method, and the stenciled gather without its stencil.
    let runs = isr::methods::REGISTRY
        .iter()
        .map(|d| (d.key(), true))
        .chain([(Method::new("multires-gather"), false)]);
    for (method, stencil) in runs {
        let settings = RenderSettings {
            method,
            ..sized("none", 160, 120, 128)
        }
        // Several submissions for the reference (4 chunks of 4,096 VPLs).
        .with(&isr::methods::reference::CHUNK, 160 * 120 * 4096)
        .with(&isr::multires::STENCIL, stencil);
        // `render` asserts that no message was reported (frames replay one
        // command buffer, so frame 2 onwards checks the hazards between frames
        // too), and reads every output back.
        let out = render(&gpu, &cornell_box(), &settings, 3);
        assert_eq!(out.stats.frames.len(), 3);
    }
}

/// Silence is only evidence if the layer would speak: two unsynchronized
/// writes to one buffer must be reported as a hazard.
#[test]
fn synchronization_validation_reports_a_real_hazard() {
    use ash::vk;
    let gpu = validating_gpu();
    let buffer = isr::vk::Buffer::new(
        &gpu,
        "hazard",
        256,
        vk::BufferUsageFlags::TRANSFER_DST,
        gpu_allocator::MemoryLocation::GpuOnly,
    )
    .unwrap();
    gpu.run_once(|cmd| unsafe {
        gpu.device.cmd_fill_buffer(cmd, buffer.buffer, 0, 256, 1);
        gpu.device.cmd_fill_buffer(cmd, buffer.buffer, 0, 256, 2);
    })
    .unwrap();
    drop(buffer);
    let messages = gpu.take_validation_messages();
    assert!(
        messages.iter().any(|m| m.contains("WRITE_AFTER_WRITE")),
        "expected a WRITE_AFTER_WRITE hazard report, got: {messages:?}"
    );
}
