//! Scene descriptions (`NAME.scene.json`) and `--light`/`--camera`: a mesh
//! placed by scale and up axis, lights and a camera replacing its own, paths
//! and orbits played by the animation machinery; the same URI policy as the
//! loaders (a mesh outside the description's folder needs
//! --allow-outside-uris; an archive mesh stays inside the archive folder);
//! bad input is an error that says where and what, before a device opens.
mod common;

use common::cli::Isr;
use common::gltf::{cornell_json, write_scene};
use common::temp_dir;
use glam::Vec3;
use isr::scene::{description, load_file, LightKind, LoadOptions};
use std::path::Path;

const QUAD: &str = "v -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nf 1 2 3 4\n";

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn error(path: &Path) -> String {
    format!(
        "{:#}",
        load_file(path, &LoadOptions::default()).unwrap_err()
    )
}

#[test]
fn lights_camera_and_paths_replace_what_the_mesh_lacks() {
    let dir = temp_dir("desc-paths");
    write(&dir, "quad.obj", QUAD);
    let p = write(
        &dir,
        "quad.scene.json",
        r#"{"mesh": "quad.obj", "scale": 2, "up": "+y",
            "lights": [
              {"type": "spot", "cone": 40, "intensity": 20,
               "path": [{"t": 0, "position": [-1, 3, 0], "target": [-1, 0, 0]},
                        {"t": 2, "position": [1, 3, 0], "target": [1, 0, 0]}]},
              {"type": "directional", "direction": [0, -1, 0]},
              {"type": "point", "position": [1, 1, 0], "orbit": {"period": 4, "center": [0, 1, 0]}}
            ],
            "camera": {"position": [0, 2, 5], "target": [0, 0, 0], "fov": 50, "znear": 0.01,
                       "path": [{"t": 0}, {"t": 2, "position": [0, 3, 4]}]}}"#,
    );
    let s = load_file(&p, &LoadOptions::default()).unwrap();
    assert_eq!(s.name, "quad");
    // Scale 2: the quad spans 4 m.
    let (lo, hi) = s.bounds().unwrap();
    assert!(
        lo.abs_diff_eq(Vec3::new(-2.0, 0.0, -2.0), 1e-6)
            && hi.abs_diff_eq(Vec3::new(2.0, 0.0, 2.0), 1e-6)
    );
    assert_eq!(s.lights.len(), 3);
    assert_eq!(s.lights[1].kind, LightKind::Directional);
    // The default intensity: a white surface facing the light reflects 1.
    assert!((s.lights[1].intensity - std::f32::consts::PI).abs() < 1e-6);
    assert!((s.camera.yfov - 50f32.to_radians()).abs() < 1e-6);
    // The path: linear between keys, clamped after the last.
    let at = |t: f32| s.pose_at(t).unwrap();
    assert!(at(0.0).lights[0]
        .position
        .abs_diff_eq(Vec3::new(-1.0, 3.0, 0.0), 1e-5));
    assert!(at(1.0).lights[0]
        .position
        .abs_diff_eq(Vec3::new(0.0, 3.0, 0.0), 1e-5));
    assert!(at(5.0).lights[0]
        .position
        .abs_diff_eq(Vec3::new(1.0, 3.0, 0.0), 1e-5));
    assert!(at(1.0).lights[0].direction.abs_diff_eq(-Vec3::Y, 1e-4));
    // The orbit: a quarter turn counter-clockwise from above in a quarter period.
    assert!(at(1.0).lights[2]
        .position
        .abs_diff_eq(Vec3::new(0.0, 1.0, -1.0), 2e-3));
    // The camera's path keeps the target.
    let c = at(2.0).camera;
    assert!(c.position().abs_diff_eq(Vec3::new(0.0, 3.0, 4.0), 1e-5));
    assert!(c
        .forward()
        .abs_diff_eq(-Vec3::new(0.0, 3.0, 4.0).normalize(), 1e-4));
    // No warning of a default light or camera.
    assert!(
        !s.warnings.iter().any(|w| w.contains("default")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn scale_and_up_place_a_gltf_and_its_own_lights_and_camera() {
    let dir = temp_dir("desc-gltf");
    write_scene(&dir, &cornell_json());
    let plain = load_file(&dir.join("scene.gltf"), &LoadOptions::default()).unwrap();
    let p = write(
        &dir,
        "z.scene.json",
        r#"{"mesh": "scene.gltf", "scale": 0.5, "up": "+z"}"#,
    );
    let s = load_file(&p, &LoadOptions::default()).unwrap();
    // +Z up turned to +Y: (x, y, z) -> (x, z, -y), then halved.
    let turn = |v: Vec3| Vec3::new(v.x, v.z, -v.y) * 0.5;
    let (lo, hi) = plain.bounds().unwrap();
    let (a, b) = (turn(lo), turn(hi));
    let (lo2, hi2) = s.bounds().unwrap();
    assert!(lo2.abs_diff_eq(a.min(b), 1e-5) && hi2.abs_diff_eq(a.max(b), 1e-5));
    let (l0, l1) = (plain.state_at(1.0).lights[0], s.state_at(1.0).lights[0]);
    assert!(
        l1.position.abs_diff_eq(turn(l0.position), 1e-5),
        "{l0:?} {l1:?}"
    );
    assert!(l1
        .direction
        .abs_diff_eq(turn(l0.direction).normalize(), 1e-5));
    assert!(s
        .camera
        .position()
        .abs_diff_eq(turn(plain.camera.position()), 1e-5));
    assert!((s.camera.znear - plain.camera.znear * 0.5).abs() < 1e-7);
}

#[test]
fn a_mesh_outside_the_folder_needs_allow_outside_uris() {
    let dir = temp_dir("desc-outside");
    std::fs::create_dir_all(dir.join("user")).unwrap();
    write(&dir, "quad.obj", QUAD);
    let p = write(
        &dir.join("user"),
        "a.scene.json",
        r#"{"mesh": "../quad.obj"}"#,
    );
    let e = error(&p);
    assert!(
        e.contains("mesh ../quad.obj") && e.contains("--allow-outside-uris"),
        "{e}"
    );
    let allowed = LoadOptions {
        allow_outside_uris: true,
        ..Default::default()
    };
    assert_eq!(load_file(&p, &allowed).unwrap().triangle_count(), 2);
    let p = write(
        &dir.join("user"),
        "b.scene.json",
        &format!(r#"{{"mesh": "{}"}}"#, dir.join("quad.obj").display()),
    );
    assert!(error(&p).contains("absolute path"), "{}", error(&p));
    // An archive mesh may not climb out of the archive folder either.
    let p = write(
        &dir.join("user"),
        "c.scene.json",
        r#"{"mesh": {"archive": "../../../etc/passwd"}}"#,
    );
    assert!(error(&p).contains("climbs out"), "{}", error(&p));
    // A description names a mesh, not another description.
    write(&dir.join("user"), "quad.obj", QUAD);
    let p = write(
        &dir.join("user"),
        "d.scene.json",
        r#"{"mesh": "d.scene.json"}"#,
    );
    assert!(
        error(&p).contains("not another description"),
        "{}",
        error(&p)
    );
    // Through the binary, with the flag.
    let ran = Isr::tiny(&dir.join("user"))
        .args([
            "--scene",
            "a.scene.json",
            "--allow-outside-uris",
            "--method",
            "none",
        ])
        .succeeds();
    assert!(
        ran.stderr.contains("the description has no lights"),
        "{}",
        ran.stderr
    );
}

#[test]
fn bad_descriptions_say_where_and_what() {
    let dir = temp_dir("desc-bad");
    write(&dir, "quad.obj", QUAD);
    let spot = |extra: &str| {
        format!(
            r#"{{"mesh": "quad.obj", "lights": [{{"type": "spot", "position": [0, 2, 0], "target": [0, 0, 0]{extra}}}]}}"#
        )
    };
    let cases = [
        ("{\"mesh\": \"quad.obj\",\n \"lihgts\": []}".to_string(), "line 2 column 9: unknown field `lihgts`, expected one of `mesh`"),
        (r#"{"mesh": 3}"#.into(), "\"mesh\" must be a file name"),
        (r#"{"mesh": "quad.obj", "scale": 0}"#.into(), "scale 0"),
        (r#"{"mesh": "quad.obj", "up": "sideways"}"#.into(), "up 'sideways'"),
        (r#"{"mesh": "quad.obj", "albedo": [2, 0, 0]}"#.into(), "from 0 to 1"),
        (spot(r#", "cone": 95"#), "light 0: cone 95"),
        (spot(r#", "intensity": -1"#), "light 0: intensity -1"),
        (spot(r#", "path": [{"t": 1}, {"t": 0}]"#), "keyframe times must increase"),
        (spot(r#", "path": [], "orbit": {"period": 1}"#), "a path or an orbit"),
        (r#"{"mesh": "quad.obj", "lights": [{"type": "laser", "position": [0, 1, 0]}]}"#.into(), "a light is spot, point or directional"),
        (r#"{"mesh": "quad.obj", "lights": [{"type": "spot", "position": [0, 1, 0], "target": [0, 1, 0]}]}"#.into(), "points nowhere"),
        (r#"{"mesh": "quad.obj", "camera": {"position": [0, 1, 5], "fov": 180}}"#.into(), "camera: fov 180"),
        (r#"{"mesh": "quad.obj", "camera": {"position": [0, 1, 5], "znear": -1}}"#.into(), "camera: znear -1"),
        (r#"{"mesh": "quad.obj", "camera": {"position": [0, 1e30, 5]}}"#.into(), "camera: position [0.0, 1e30, 5.0] reaches beyond 1e6 m"),
        (r#"{"mesh": "quad.obj", "room": {"size": [1, 0, 1]}}"#.into(), "room size"),
    ];
    for (text, what) in cases {
        let p = write(&dir, "bad.scene.json", &text);
        let e = error(&p);
        assert!(
            e.contains("bad.scene.json") && e.contains(what),
            "{text}: {e}"
        );
    }
    // Too large to be a description.
    let p = write(&dir, "big.scene.json", &" ".repeat(2 << 20));
    assert!(
        error(&p).contains("more than the limit of 1 MiB"),
        "{}",
        error(&p)
    );
}

#[test]
fn light_and_camera_options_are_checked_before_a_device_opens() {
    let dir = temp_dir("desc-cli");
    for (args, what) in [
        (vec!["--light", "spot:position=1,2"], "a vector is X,Y,Z"),
        (
            vec!["--light", "laser:position=0,1,0"],
            "spot, point or directional",
        ),
        (vec!["--light", "spot:position=0,1,0"], "needs a target"),
        (
            vec!["--light", "spot:position=0,1,0:target=0,0,0:cone=120"],
            "cone 120",
        ),
        (
            vec!["--light", "point:position=0,1,0:intensity=nan"],
            "not a finite number",
        ),
        (
            vec!["--light", "directional:colour=1,1,1"],
            "needs a direction",
        ),
        (vec!["--light", "point:position=0,1,0:size=3"], "'size'"),
        (vec!["--camera", "target=0,0,0"], "needs a position"),
        (vec!["--camera", "position=0,1,5:fov=0"], "fov 0"),
    ] {
        // A device error would say "Vulkan"; these fail in parsing.
        let e = Isr::tiny(&dir)
            .env("VK_ICD_FILENAMES", "/nonexistent.json")
            .args(&args)
            .fails();
        assert!(e.contains(what) && !e.contains("Vulkan"), "{args:?}: {e}");
    }
    for cmd in ["render", "view"] {
        let help = Isr::new(cmd).arg("--help").succeeds().stdout;
        assert!(
            help.contains("--light <SPEC>") && help.contains("spot:position=X,Y,Z:target=X,Y,Z"),
            "{help}"
        );
        assert!(
            help.contains("--camera <SPEC>") && help.contains("position=X,Y,Z[:target=X,Y,Z]"),
            "{help}"
        );
    }
    // Several lights replace the built-in box's spot.
    let ran = Isr::tiny(&dir)
        .args([
            "--method",
            "none",
            "--light",
            "point:position=0,1.5,0",
            "--light",
            "directional:direction=0.3,-1,0.2:intensity=2",
            "--camera",
            "position=0,1,3.5:target=0,1,0",
        ])
        .succeeds();
    assert!(
        ran.stdout.contains("rsm-cube") || ran.stdout.contains("rsm"),
        "{}",
        ran.stdout
    );
}

#[test]
fn a_missing_archive_folder_says_how_to_get_it() {
    let dir = temp_dir("desc-archive");
    let e = Isr::tiny(&dir)
        .env(description::ARCHIVE_VARIABLE, dir.join("nowhere"))
        .args(["--scene"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/archive/sponza.scene.json"))
        .fails();
    assert!(
        e.contains("nowhere is not a folder")
            && e.contains(
                "set ISR_SCENES to the folder that holds sibenik/, sponza/, conference/ and bunny/"
            ),
        "{e}"
    );
    let e = Isr::new("bench")
        .env(description::ARCHIVE_VARIABLE, dir.join("nowhere"))
        .args(["--scenes", "sponza", "--out-dir"])
        .arg(dir.join("b"))
        .fails();
    assert!(
        e.contains("bench scene sponza") && e.contains("ISR_SCENES"),
        "{e}"
    );
}

/// Orbit centres and fields of view held to the limits the glTF loader
/// holds positions and cameras to (an orbit about [1e30, 0, 0] put the light
/// 1e30 m away, fovs of 1e-40 and 1e-20 degrees rendered black or half
/// black, exit 0), refused with why; and the narrowest fov allowed renders
/// every pixel lit.
#[test]
fn orbit_centres_and_fields_of_view_are_held_to_the_limits() {
    let dir = temp_dir("desc-limits");
    write(&dir, "quad.obj", QUAD);
    let point = |orbit: &str| {
        format!(
            r#"{{"mesh": "quad.obj", "lights": [{{"type": "point", "position": [0.5, 2, 0], "orbit": {orbit}}}]}}"#
        )
    };
    let camera = |fields: &str| {
        format!(r#"{{"mesh": "quad.obj", "camera": {{"position": [0, 1, 3]{fields}}}}}"#)
    };
    for (text, what) in [
        (
            point(r#"{"period": 4, "center": [1e30, 0, 0]}"#),
            "light 0: orbit center [1e30, 0.0, 0.0] reaches beyond 1e6 m",
        ),
        // A centre within the budget, but a circle through the light that
        // leaves it.
        (
            point(r#"{"period": 4, "center": [-9e5, 0, 0]}"#),
            "light 0: the orbit about [-900000, 0, 0] reaches 1.800e6 m",
        ),
        (
            camera(r#", "orbit": {"period": 4, "center": [0, -1e30, 0]}"#),
            "camera: orbit center [0.0, -1e30, 0.0] reaches beyond 1e6 m",
        ),
        (
            camera(r#", "fov": 1e-40"#),
            "camera: fov 1e-40 (degrees): the vertical field of view must be between 1.15e-4 and",
        ),
        (camera(r#", "fov": 1e-20"#), "camera: fov 1e-20 (degrees)"),
    ] {
        let p = write(&dir, "bad.scene.json", &text);
        let e = error(&p);
        assert!(e.contains(what), "{text}: {e}");
    }
    // --camera alike, before a device opens.
    let e = Isr::tiny(&dir)
        .env("VK_ICD_FILENAMES", "/nonexistent.json")
        .args(["--camera", "position=0,1,5:fov=1e-20"])
        .fails();
    assert!(
        e.contains("fov 1e-20 (degrees)") && !e.contains("Vulkan"),
        "{e}"
    );
    // Just wider than the narrowest: the built-in box's floor, in the spot's
    // inner cone, fills the view, lit in every pixel. The point is lit by
    // the path tracer's visibility too (the floor at z = 0.8 m once chosen
    // here lies 1 cm inside the short block's shadow, lit only through a
    // 32-texel shadow map's blur).
    let fov = isr::scene::MIN_YFOV.to_degrees() * 1.01;
    let mut scene = isr::scene::cornell::cornell_box();
    scene.animation = None;
    let target = Vec3::new(-0.3, 0.0, 0.9);
    assert!(isr::pathtrace::Occluders::new(&scene).visible(
        target,
        Vec3::Y,
        scene.lights[0].position
    ));
    let spec = description::parse_camera(&format!("position=0,1,3.4:target=-0.3,0,0.9:fov={fov}"))
        .unwrap();
    description::apply(&mut scene, &[], Some(&spec)).unwrap();
    let gpu = common::gpu();
    let r = common::render(&gpu, &scene, &common::sized("none", 32, 32, 32), 1).readback;
    let dark = r
        .direct
        .iter()
        .filter(|p| (p[0] + p[1] + p[2]).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
        .count();
    assert_eq!(dark, 0, "{dark} pixels unlit at fov {fov} degrees");
}

/// What descriptions got wrong in their messages: a sun direction of
/// [1e30, -1e30, 0] (its length overflows in f32: refused as pointing
/// nowhere) and a byte-order mark before the JSON (refused as "line 1
/// column 1: expected value") load; file text in a message is escaped
/// and cut short.
#[test]
fn directions_of_any_length_a_byte_order_mark_and_escaped_messages() {
    let dir = temp_dir("desc-text");
    write(&dir, "quad.obj", QUAD);
    let p = write(
        &dir,
        "sun.scene.json",
        "\u{feff}{\"mesh\": \"quad.obj\", \"lights\": [{\"type\": \"directional\", \"direction\": [1e30, -1e30, 0]}]}",
    );
    let s = load_file(&p, &LoadOptions::default()).unwrap();
    assert!(
        s.lights[0]
            .direction
            .abs_diff_eq(Vec3::new(1.0, -1.0, 0.0).normalize(), 1e-6),
        "{:?}",
        s.lights[0].direction
    );
    for (text, shows) in [
        (
            // JSON's escape for ESC: the string holds the byte itself.
            r#"{"mesh": "quad.obj", "up": "\u001b[2J"}"#.to_string(),
            "up '\\u{1b}[2J'".to_string(),
        ),
        (
            r#"{"mesh": "quad.obj", "\u001b[2J": 1}"#.to_string(),
            "unknown field `\\u{1b}[2J`".to_string(),
        ),
        (
            format!("{{\"mesh\": \"{}.obj\"}}", "m".repeat(100_000)),
            "(100004 bytes in all)".to_string(),
        ),
    ] {
        let p = write(&dir, "bad.scene.json", &text);
        let e = error(&p);
        assert!(
            e.contains(&shows) && !e.contains('\u{1b}') && e.len() < 2000,
            "{} bytes: {}",
            e.len(),
            &e[..e.len().min(2000)]
        );
    }
}
