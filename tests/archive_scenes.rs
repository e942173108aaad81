//! The archive scenes (Sibenik, Sponza, the conference room, the bunny),
//! read from the archive folder (`ISR_SCENES`, or `../shared/scenes` beside
//! the repository; README, "Scenes from the archives"): each loads and
//! renders one HISR frame at 64x64 under validation, with its light and
//! camera placed by its scene description and, through the binary, by
//! `--light` and `--camera` on a bare OBJ; each of Sponza's ten textures
//! reaches the G-buffer on every device; the bench knows the scenes and their
//! sizes.
//! The scenes are loaded once per test binary. Without the archive the
//! tests fail and say where to get it.
mod common;

use common::cli::Isr;
use common::{assert_validation_clean, sized, temp_dir, validating_gpu};
use glam::{Vec2, Vec3};
use isr::bench::scenes;
use isr::renderer::Renderer;
use isr::scene::description::{archive_hint, archive_root};
use isr::scene::{Camera, Scene};
use std::path::PathBuf;
use std::sync::OnceLock;

/// The archive folder, or a failure that says how to get it.
fn archive() -> PathBuf {
    let root = archive_root();
    for s in [
        "sibenik/sibenik.obj",
        "sponza/sponza.obj",
        "conference/conference.obj",
        "bunny/bunny.obj",
    ] {
        assert!(
            root.join(s).is_file(),
            "{} is missing: {}",
            root.join(s).display(),
            archive_hint()
        );
    }
    root
}

/// The four scenes as the bench loads them (their descriptions), once.
fn loaded() -> &'static Vec<(&'static str, Scene)> {
    static SCENES: OnceLock<Vec<(&'static str, Scene)>> = OnceLock::new();
    SCENES.get_or_init(|| {
        archive();
        scenes::ARCHIVE
            .iter()
            .map(|s| {
                let scene = scenes::build(s.name).unwrap_or_else(|e| panic!("{}: {e:#}", s.name));
                (s.name, scene)
            })
            .collect()
    })
}

#[test]
fn each_archive_scene_renders_a_hisr_frame_lit_and_framed_by_its_description() {
    let gpu = validating_gpu();
    let expected = [
        ("sibenik", 73_556),
        ("sponza", 66_445),
        ("conference", 277_552),
        ("bunny", 69_459),
    ];
    for ((name, scene), (want, triangles)) in loaded().iter().zip(expected) {
        assert_eq!(*name, want);
        // The OBJ's triangles less its degenerate ones (the bunny: and the
        // room's eight).
        assert_eq!(scene.triangle_count(), triangles, "{name}");
        assert!(scene.animation_duration().is_some(), "{name} moves");
        let mut r = Renderer::new(&gpu, scene, &sized("hisr", 64, 64, 64)).unwrap();
        r.update(&scene.pose_at(0.5).unwrap()).unwrap();
        r.render_frames(1, |_| {}).unwrap();
        let out = r.readback().unwrap();
        drop(r);
        assert_validation_clean(&gpu);
        let n = out.position.len();
        let geometry = out.position.iter().filter(|p| p[3] > 0.0).count();
        let lit = out
            .direct
            .iter()
            .filter(|d| d[0] + d[1] + d[2] > 1e-3)
            .count();
        let bounced = out
            .indirect
            .iter()
            .filter(|e| e[0] + e[1] + e[2] > 1e-4)
            .count();
        // The camera looks at the scene (not past it or at a wall's back)
        // and the light falls where it looks.
        assert!(
            geometry > n * 9 / 10,
            "{name}: {geometry} of {n} pixels see geometry"
        );
        assert!(lit > n / 10, "{name}: {lit} of {n} pixels lit directly");
        assert!(
            bounced > n / 4,
            "{name}: {bounced} of {n} pixels get indirect light"
        );
        // Motion: the light moves between the bench's first two frames.
        let (a, b) = (scene.pose_at(0.0).unwrap(), scene.pose_at(0.1).unwrap());
        assert_ne!(a.lights[0], b.lights[0], "{name}: the light moves");
    }
}

/// The lights and cameras the descriptions give, as `--light` and
/// `--camera` on the bare OBJ (the conference room is in file units,
/// 1/0.003 of a metre).
#[test]
fn each_archive_obj_renders_a_hisr_frame_lit_and_framed_from_the_command_line() {
    let root = archive();
    let dir = temp_dir("archive-cli");
    let cases = [
        (
            "sibenik/sibenik.obj",
            "spot:position=-14,2,0:target=-8,-14,0:cone=35:intensity=1500",
            "position=-17,-10.5,0:target=8,-7,0:fov=60",
        ),
        (
            "sponza/sponza.obj",
            "directional:direction=-0.9,-1,0.3:intensity=4",
            "position=-13,2.5,0:target=10,5,0:fov=60",
        ),
        (
            "conference/conference.obj",
            "spot:position=-133,533,-167:target=133,100,-167:cone=50",
            "position=1100,433,300:target=167,117,-267:fov=65",
        ),
        (
            "bunny/bunny.obj",
            "point:position=0.1,0.3,0.2:intensity=0.2",
            "position=0,0.15,0.45:target=-0.02,0.09,0:fov=30",
        ),
    ];
    for (file, light, camera) in cases {
        let name = file.split('/').next().unwrap();
        let png = dir.join(format!("{name}.png"));
        let ran = Isr::render(&dir)
            .args([
                "--method",
                "hisr",
                "--width",
                "64",
                "--height",
                "64",
                "--rsm",
                "64",
                "--frames",
                "1",
                "--validate",
            ])
            .arg("--scene")
            .arg(root.join(file))
            .args(["--light", light, "--camera", camera, "--png"])
            .arg(&png)
            .arg("--out")
            .arg(dir.join(format!("{name}.exr")))
            .succeeds();
        // The command line's light and camera replaced the defaults.
        assert!(!ran.stderr.contains("default spot light"), "{}", ran.stderr);
        assert!(!ran.stderr.contains("default camera"), "{}", ran.stderr);
        // Every texture is sampled as it is: none replaced by its mean
        // colour, none shrunk.
        assert!(!ran.stderr.contains("mean colour"), "{}", ran.stderr);
        assert!(!ran.stderr.contains("shrunk"), "{}", ran.stderr);
        let img = image::open(&png).unwrap().to_rgb8();
        let bright = img
            .pixels()
            .filter(|p| p.0.iter().map(|&c| c as u32).sum::<u32>() > 30)
            .count();
        assert!(
            bright > (img.width() * img.height()) as usize / 10,
            "{name}: {bright} pixels not dark:\n{}",
            ran.stderr
        );
    }
}

/// Each of Sponza's ten textures: all ten are bound, each in a layer of its
/// own, and the G-buffer's albedo where the camera looks at one of the
/// texture's triangles is Kd times the texture decoded here, at that
/// point's texture coordinates (bilinear, in linear values, repeat), at a
/// point whose texel is unlike the texture's mean. One renderer, the
/// camera moved between frames.
#[test]
fn each_textured_sponza_albedo_reaches_the_g_buffer() {
    let root = archive();
    let gpu = validating_gpu();
    let (_, sponza) = loaded().iter().find(|(n, _)| *n == "sponza").unwrap();
    let mut s = sponza.clone();
    s.animation = None;
    assert_eq!(s.textures.len(), 10);
    let mut r = Renderer::new(&gpu, &s, &sized("none", 65, 65, 64)).unwrap();
    let plan = &r.scene.plan;
    let layers: std::collections::HashSet<(u32, u32)> =
        plan.placements.iter().map(|p| (p.array, p.layer)).collect();
    assert_eq!(layers.len(), 10, "{plan:?}");
    for (k, texture) in s.textures.iter().enumerate() {
        let (expected, uv, mean, camera) = textured_view(&root, &s, k);
        let mut state = s.rest_state();
        state.camera = camera;
        r.update(&state).unwrap();
        r.render_frames(1, |_| {}).unwrap();
        let out = r.readback().unwrap();
        let got = Vec3::from_slice(&out.albedo[32 * 65 + 32][..3]);
        assert!(
            (got - expected).abs().max_element() < 0.02,
            "texture {} at uv {uv}: G-buffer albedo {got}, decoded texel times Kd {expected} (mean {mean})",
            texture.name
        );
    }
    drop(r);
    assert_validation_clean(&gpu);
}

/// For texture `k` of Sponza `s`: Kd times the texture decoded here at the
/// centroid of one of the largest triangles mapped with it whose texel there
/// is unlike the texture's mean (so that a wrong texture or texture
/// coordinate shows), that centroid's texture coordinates, Kd times the
/// mean, and a camera just in front of the centroid looking at it along
/// the normal (65x65, so that the middle pixel's centre is the image's
/// centre).
fn textured_view(root: &std::path::Path, s: &Scene, k: usize) -> (Vec3, Vec2, Vec3, Camera) {
    let texture = &s.textures[k];
    let decoded = image::open(root.join("sponza/textures").join(&texture.name))
        .unwrap_or_else(|e| panic!("{}: {e}", texture.name))
        .to_rgba8();
    assert_eq!(
        (decoded.width(), decoded.height()),
        (texture.width, texture.height)
    );
    let linear = |c: u8| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let texel = |x: i64, y: i64| {
        let (w, h) = (decoded.width() as i64, decoded.height() as i64);
        let p = decoded
            .get_pixel(x.rem_euclid(w) as u32, y.rem_euclid(h) as u32)
            .0;
        Vec3::new(linear(p[0]), linear(p[1]), linear(p[2]))
    };
    let bilinear = |uv: Vec2| {
        let x = uv.x * decoded.width() as f32 - 0.5;
        let y = uv.y * decoded.height() as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        texel(x0, y0) * (1.0 - fx) * (1.0 - fy)
            + texel(x0 + 1, y0) * fx * (1.0 - fy)
            + texel(x0, y0 + 1) * (1.0 - fx) * fy
            + texel(x0 + 1, y0 + 1) * fx * fy
    };
    let pixels = decoded.pixels().count() as f32;
    let mean = decoded
        .pixels()
        .map(|p| Vec3::new(linear(p.0[0]), linear(p.0[1]), linear(p.0[2])))
        .sum::<Vec3>()
        / pixels;
    let mut candidates = vec![];
    for inst in &s.instances {
        let mesh = &s.meshes[inst.mesh];
        let m = &s.materials[mesh.material];
        if m.texture != Some(k) {
            continue;
        }
        for t in mesh.indices.chunks_exact(3) {
            let v = |k: usize| &mesh.vertices[t[k] as usize];
            let p = |k: usize| {
                inst.world_from_object
                    .transform_point3(Vec3::from(v(k).position))
            };
            let n = (p(1) - p(0)).cross(p(2) - p(0));
            let centroid = (p(0) + p(1) + p(2)) / 3.0;
            let uv = (Vec2::from(v(0).uv) + Vec2::from(v(1).uv) + Vec2::from(v(2).uv)) / 3.0;
            candidates.push((
                n.length(),
                centroid,
                n.normalize(),
                uv,
                m.base_color.truncate(),
            ));
        }
    }
    assert!(
        !candidates.is_empty(),
        "no material uses texture {}",
        texture.name
    );
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (area2, centroid, normal, uv, kd) = *candidates
        .iter()
        .take(200)
        .find(|c| (c.4 * bilinear(c.3) - c.4 * mean).abs().max_element() > 0.05)
        .unwrap_or_else(|| {
            panic!(
                "texture {}: no large triangle whose texel differs from the mean",
                texture.name
            )
        });
    let d = 0.02 * area2.sqrt();
    let camera = Camera::look_at(
        centroid + normal * d,
        centroid,
        pick_up(normal),
        5f32.to_radians(),
        d * 0.1,
    );
    (kd * bilinear(uv), uv, kd * mean, camera)
}

fn pick_up(n: Vec3) -> Vec3 {
    if n.dot(Vec3::Y).abs() > 0.9 {
        Vec3::X
    } else {
        Vec3::Y
    }
}

/// `--scenes archive` is the four scenes at their own 64x64 (RSM 128) and
/// 3 frames,
/// unless the command line sets the size or frames.
#[test]
fn the_bench_runs_the_archive_scenes_at_their_own_size() {
    let args = isr::bench::BenchArgs {
        scenes: vec!["archive".into()],
        ..Default::default()
    };
    let plan = args.plan().unwrap();
    let names: Vec<&str> = plan.scenes.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["sibenik", "sponza", "conference", "bunny"]);
    for s in &plan.scenes {
        let p = plan.for_scene(s);
        assert_eq!(
            (p.base.width, p.base.height, p.base.rsm_resolution, p.frames),
            (64, 64, 128, 3)
        );
    }
    let args = isr::bench::BenchArgs {
        scenes: vec!["sponza".into(), "cornell".into()],
        width: Some(96),
        ..Default::default()
    };
    let plan = args.plan().unwrap();
    let got: Vec<_> = plan
        .scenes
        .iter()
        .map(|s| {
            let p = plan.for_scene(s);
            (p.base.width, p.base.rsm_resolution, p.frames)
        })
        .collect();
    // The size is the command line's; the frames stay each scene's own.
    assert_eq!(got, [(96, 128, 3), (96, 128, 6)]);
    // The default run is the five stress scenes, as before.
    let plan = isr::bench::BenchArgs::default().plan().unwrap();
    assert_eq!(plan.scenes.len(), 5);
}

/// Each archive OBJ, bare (no description, `--light` or `--camera`), at
/// 128x128 with the default method: the placed camera sees geometry in a
/// quarter of the image or more and the placed light lights half of that
/// or more (`placement`). The loader's spot and +Z camera alone: Sponza
/// and the conference room black, Sibenik 8% lit, the bunny 5%.
#[test]
fn each_archive_obj_rendered_bare_is_framed_and_lit() {
    let root = archive();
    let dir = temp_dir("archive-bare");
    for (file, inside) in [
        ("sponza/sponza.obj", true),
        ("sibenik/sibenik.obj", true),
        ("conference/conference.obj", true),
        ("bunny/bunny.obj", false),
    ] {
        let name = file.split('/').next().unwrap();
        let seen = common::framing::render_bare(&dir, name, &root.join(file), 128, &[]);
        let line = seen
            .stderr
            .lines()
            .find(|l| l.contains("placed"))
            .unwrap_or_default();
        eprintln!(
            "{name}: geometry {:.0}%, lit {:.0}% of it: {line}",
            100.0 * seen.geometry as f64 / seen.pixels as f64,
            100.0 * seen.lit as f64 / seen.geometry.max(1) as f64
        );
        assert!(seen.framed_and_lit(), "{name}: {seen:?}");
        assert_eq!(line.contains("standing inside"), inside, "{name}: {line}");
        // Sponza's roof is open: a sun comes through it.
        assert_eq!(line.contains("a sun"), name == "sponza", "{name}: {line}");
    }
}
