//! A hostile OBJ/MTL corpus: each case ends in a clear error that names the
//! file and line, or in a render with warnings, never a panic, a hang or a
//! read outside the scene's folder (issue 27). Most run through the release
//! binary (`common::cli`); the bounded read of a file of 10^8 `v` lines and
//! the budgets run in process, where the bytes taken and allocated can be
//! counted. Modules: `budgets` (memory in proportion to the file, one
//! warning per kind), `images` (normals, texture coordinates, triangle
//! order), `text` (byte-order marks, line ends, escapes, messages).
#[path = "obj_hostile/budgets.rs"]
mod budgets;
mod common;
#[path = "obj_hostile/images.rs"]
mod images;
#[path = "obj_hostile/text.rs"]
mod text;

use common::cli::Isr;
use common::gltf::{png, png_header_only};
use common::measure::{peak_allocated, Counting};
use common::temp_dir;
use isr::scene::limits::Limits;
use isr::scene::{obj_load, LoadOptions};
use std::io::BufRead;
use std::path::Path;

#[global_allocator]
static ALLOC: Counting = Counting;

/// A unit quad (two triangles) over the floor, seen by the default camera.
const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nf 1 2 3 4\n";

/// Renders `dir/scene.obj` holding `obj`; the clean failure's message.
fn fails(dir: &Path, obj: &str) -> String {
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    Isr::tiny(dir).args(["--scene", "scene.obj"]).fails()
}

/// Renders `dir/scene.obj` holding `obj`; its warnings (stderr).
fn renders(dir: &Path, obj: &str) -> String {
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    Isr::tiny(dir)
        .args(["--scene", "scene.obj"])
        .succeeds()
        .stderr
}

#[test]
fn truncated_lines_are_errors_naming_the_line() {
    let dir = temp_dir("obj-truncated");
    for (obj, line, what) in [
        ("v 0 0 0\nv 1 0 0\nv 1 0", 3, "cut short"),
        ("v 0 0 0\nv 1 0 0\nv 1 0 -1\nf 1 2", 4, "cut short"),
        ("v 0 0 0\nv 1 0 0\nv 1 0 -1\nf 1 2 3/", 0, ""),
        (
            "v 0 0 0\nv 1 0 0\nv 1 0 -1\nf 1 2 3/9",
            4,
            "texture coordinate 9",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 1 0 -1\nf 1 2 3 x",
            4,
            "'x' is not an index",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 1 0 -1\nvt 0.5\nvn 0 1\n",
            5,
            "has 2 number(s)",
        ),
        ("v 0 0 0\nv 1 0 0\nv 1 0 -1\nf\n", 4, "has 0"),
        ("v 0 0 0.\nv 1e\n", 2, "'1e' is not a number"),
    ] {
        if line == 0 {
            // A trailing slash names no texture coordinate: a face as OBJ
            // reads it.
            renders(&dir, obj);
            continue;
        }
        let e = fails(&dir, obj);
        assert!(
            e.contains(&format!("scene.obj line {line}")) && e.contains(what),
            "{obj:?}: {e}"
        );
    }
}

#[test]
fn indices_of_zero_negative_or_past_the_end() {
    let dir = temp_dir("obj-indices");
    let three = "v 0 0 0\nv 1 0 0\nv 1 0 -1\n";
    let e = fails(&dir, &format!("{three}f 0 1 2\n"));
    assert!(e.contains("line 4") && e.contains("index 0"), "{e}");
    let e = fails(&dir, &format!("{three}f 1 2 4\n"));
    assert!(
        e.contains("line 4") && e.contains("refers to vertex 4, but 3 are defined"),
        "{e}"
    );
    let e = fails(&dir, &format!("{three}f -1 -2 -4\n"));
    assert!(e.contains("line 4") && e.contains("vertex -4"), "{e}");
    let e = fails(&dir, &format!("{three}f 1 2 99999999999999999999\n"));
    assert!(e.contains("line 4") && e.contains("not an index"), "{e}");
    let e = fails(&dir, &format!("{three}vn 0 1 0\nf 1//1 2//2 3//1\n"));
    assert!(e.contains("line 5") && e.contains("normal 2"), "{e}");
    // Relative indices count back from the last vertex defined: a render.
    renders(&dir, &format!("{three}f -3 -2 -1\n"));
}

#[test]
fn nan_and_1e39_coordinates_are_errors() {
    let dir = temp_dir("obj-nan");
    for (bad, shows) in [("NaN", "NaN"), ("1e39", "inf"), ("-inf", "-inf")] {
        let e = fails(&dir, &format!("v 0 0 0\nv 1 {bad} 0\nv 1 0 -1\nf 1 2 3\n"));
        assert!(
            e.contains("scene.obj line 2") && e.contains(shows) && e.contains("finite"),
            "{bad}: {e}"
        );
    }
    let e = fails(&dir, "v 0 0 0\nv 1 0 0\nv 1 0 -1\nvt 0 nan\nf 1 2 3\n");
    assert!(e.contains("line 4"), "{e}");
    // Finite but far beyond the coordinate budget.
    let e = fails(&dir, "v 0 0 0\nv 1e30 0 0\nv 1 0 -1\nf 1 2 3\n");
    assert!(e.contains("too large"), "{e}");
}

/// One face of 10^6 vertices (a convex polygon on a circle) fans into
/// 999,998 triangles and renders; under a tighter triangle budget it is
/// refused at its line, as the triangles are counted.
#[test]
fn a_face_of_a_million_vertices() {
    let dir = temp_dir("obj-million");
    let n = 1_000_000;
    let mut obj = String::with_capacity(40 * n);
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        obj += &format!("v {:.7} 0 {:.7}\n", a.cos(), -a.sin());
    }
    obj += "f";
    for k in 1..=n {
        obj += &format!(" {k}");
    }
    obj += "\n";
    std::fs::write(dir.join("scene.obj"), &obj).unwrap();
    let ran = Isr::tiny(&dir)
        .args(["--scene", "scene.obj", "--method", "none"])
        .succeeds();
    // 999,998 triangles: those of zero area (thin ones next to the first
    // vertex, whose corners the file's 7 decimals put on one line) skipped,
    // the rest rendered.
    let count = |what: &str| -> u64 {
        let at = ran
            .stderr
            .find(what)
            .unwrap_or_else(|| panic!("{what}: {}", ran.stderr));
        let before = ran.stderr[..at].trim_end();
        before[before.rfind(' ').map_or(0, |i| i + 1)..]
            .parse()
            .unwrap()
    };
    let (degenerate, rendered) = (
        count("degenerate triangle(s)"),
        count("triangle(s) without them"),
    );
    assert_eq!(degenerate + rendered, 999_998, "{}", ran.stderr);
    assert!(rendered > 999_000);
    let options = LoadOptions {
        limits: Limits {
            triangles: 1 << 16,
            ..Limits::DEFAULT
        },
        ..Default::default()
    };
    let e = obj_load::load_with(&dir.join("scene.obj"), &options).unwrap_err();
    let e = format!("{e:#}");
    assert!(
        e.contains(&format!("line {}", n + 1)) && e.contains("triangles; the limit is 65536"),
        "{e}"
    );
}

#[test]
fn a_library_that_names_itself_or_the_obj_is_read_once() {
    let dir = temp_dir("obj-self");
    std::fs::write(
        dir.join("self.mtl"),
        "mtllib self.mtl\nnewmtl grey\nKd 0.5 0.5 0.5\nmtllib self.mtl\n",
    )
    .unwrap();
    let w = renders(
        &dir,
        &format!("mtllib self.mtl\nmtllib self.mtl\nusemtl grey\n{QUAD}"),
    );
    assert!(
        w.contains("MTL keys ignored (a material library includes no other files): 'mtllib' (self.mtl line 1, and 1 more)"),
        "{w}"
    );
    // The OBJ as its own library: its lines are MTL keys to ignore.
    let w = renders(&dir, &format!("mtllib scene.obj\n{QUAD}"));
    assert!(
        w.contains("MTL keys ignored")
            && w.contains("'v' (scene.obj line 2, and 3 more")
            && w.contains("'f' (scene.obj line 6"),
        "{w}"
    );
}

#[test]
fn missing_libraries_and_textures_are_errors_naming_the_line() {
    let dir = temp_dir("obj-missing");
    let e = fails(&dir, &format!("# a scene\nmtllib gone.mtl\n{QUAD}"));
    assert!(
        e.contains("scene.obj line 2: mtllib gone.mtl") && e.contains("gone.mtl"),
        "{e}"
    );
    std::fs::write(dir.join("m.mtl"), "newmtl a\nKd 1 1 1\nmap_Kd gone.png\n").unwrap();
    let e = fails(&dir, &format!("mtllib m.mtl\nusemtl a\n{QUAD}"));
    assert!(
        e.contains("m.mtl line 3: map_Kd gone.png") && e.contains("gone.png"),
        "{e}"
    );
    // A texture that is not an image: an error, as in a glTF.
    std::fs::write(dir.join("junk.png"), b"not an image at all").unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl a\nmap_Kd junk.png\n").unwrap();
    let e = fails(&dir, &format!("mtllib m.mtl\nusemtl a\n{QUAD}"));
    assert!(
        e.contains("m.mtl line 2") && e.contains("cannot decode"),
        "{e}"
    );
    // Malformed MTL lines.
    for (mtl, line, what) in [
        ("newmtl a\nKd 0.5 0.5\n", 2, "cut short"),
        ("Kd 1 1 1\n", 1, "before any newmtl"),
        ("newmtl a\nKd 1 -1 1\n", 2, "non-negative"),
        ("newmtl\n", 1, "names no material"),
        ("newmtl a\nmap_Kd -s 1 1 1\n", 2, ""),
    ] {
        std::fs::write(dir.join("m.mtl"), mtl).unwrap();
        let e = fails(&dir, &format!("mtllib m.mtl\nusemtl a\n{QUAD}"));
        assert!(
            e.contains(&format!("m.mtl line {line}")) && e.contains(what),
            "{mtl:?}: {e}"
        );
    }
}

/// Texture (and library) paths that leave the folder, devices and FIFOs:
/// refused by name, before anything is read; a FIFO does not block.
#[test]
fn texture_paths_outside_the_folder_devices_and_fifos_are_refused() {
    let dir = temp_dir("obj-paths");
    std::fs::create_dir_all(dir.join("scene")).unwrap();
    let scene = dir.join("scene");
    std::fs::write(dir.join("outside.png"), png(1, 1, &[255, 0, 0])).unwrap();
    let _ = std::process::Command::new("mkfifo")
        .arg(scene.join("pipe"))
        .status();
    let _ = std::process::Command::new("mkfifo")
        .arg(scene.join("pipe.mtl"))
        .status();
    let _ = std::os::unix::fs::symlink("/etc/passwd", scene.join("link.png"));
    let cases = [
        ("../outside.png", "climbs out of the scene file's folder"),
        ("/etc/passwd", "absolute path"),
        ("/dev/zero", "absolute path"),
        ("link.png", "symbolic link"),
        ("pipe", "a FIFO"),
        ("sub\\..\\..\\outside.png", "climbs out"),
    ];
    for (texture, what) in cases {
        std::fs::write(scene.join("m.mtl"), format!("newmtl a\nmap_Kd {texture}\n")).unwrap();
        let e = fails(&scene, &format!("mtllib m.mtl\nusemtl a\n{QUAD}"));
        assert!(
            e.contains("m.mtl line 2") && e.contains(what),
            "{texture}: {e}"
        );
    }
    // With --allow-outside-uris a path may leave the folder, but only
    // regular files are read.
    std::fs::write(scene.join("m.mtl"), "newmtl a\nmap_Kd /dev/zero\n").unwrap();
    std::fs::write(
        scene.join("scene.obj"),
        format!("mtllib m.mtl\nusemtl a\n{QUAD}"),
    )
    .unwrap();
    let e = Isr::tiny(&scene)
        .args(["--scene", "scene.obj", "--allow-outside-uris"])
        .fails();
    assert!(e.contains("is a device"), "{e}");
    // Libraries: the same rules.
    for (library, what) in [
        ("../m.mtl", "climbs out"),
        ("/etc/passwd", "absolute path"),
        ("pipe.mtl", "a FIFO"),
    ] {
        let e = fails(&scene, &format!("mtllib {library}\n{QUAD}"));
        assert!(
            e.contains("scene.obj line 1") && e.contains(what),
            "{library}: {e}"
        );
    }
    // The OBJ itself.
    let e = Isr::tiny(&scene).args(["--scene", "pipe.obj"]).fails();
    assert!(e.contains("pipe.obj"), "{e}");
    let _ = std::process::Command::new("mkfifo")
        .arg(scene.join("fifo.obj"))
        .status();
    let e = Isr::tiny(&scene).args(["--scene", "fifo.obj"]).fails();
    assert!(e.contains("a FIFO"), "{e}");
}

#[test]
fn a_100k_by_100k_png_header_is_refused_before_decoding() {
    let dir = temp_dir("obj-huge-png");
    std::fs::write(dir.join("huge.png"), png_header_only(100_000, 100_000)).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl a\nKd 1 1 1\nmap_Kd huge.png\n").unwrap();
    std::fs::write(
        dir.join("scene.obj"),
        format!("mtllib m.mtl\nusemtl a\n{QUAD}"),
    )
    .unwrap();
    let ran = Isr::tiny(&dir).args(["--scene", "scene.obj"]).run();
    let peak = ran.peak_kib;
    let e = ran.clean_failure();
    assert!(
        e.contains("m.mtl line 3")
            && e.contains("100000x100000 pixels; textures may be at most 16384x16384"),
        "{e}"
    );
    if let Some(kib) = peak {
        assert!(kib < 512 << 10, "isr used {kib} KiB at its peak");
    }
}

/// CRLF line ends load as LF ones do: the same triangles, material and
/// texture (a name ending in '\r' would be a missing file, or a material
/// no `usemtl` finds).
#[test]
fn crlf_line_endings() {
    let dir = temp_dir("obj-crlf");
    std::fs::write(
        dir.join("t.png"),
        png(2, 2, &[255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]),
    )
    .unwrap();
    let mtl = "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd t.png\n";
    let obj = format!(
        "mtllib m.mtl\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl a\no quad\n{}",
        QUAD.replace("f 1 2 3 4", "f 1/1 2/2 3/3 4/4")
    );
    let load = |crlf: bool| {
        let fix = |s: &str| {
            if crlf {
                s.replace('\n', "\r\n")
            } else {
                s.to_string()
            }
        };
        std::fs::write(dir.join("m.mtl"), fix(mtl)).unwrap();
        std::fs::write(dir.join("scene.obj"), fix(&obj)).unwrap();
        obj_load::load(&dir.join("scene.obj")).unwrap()
    };
    let (lf, crlf) = (load(false), load(true));
    assert_eq!(crlf.triangle_count(), 2);
    assert_eq!(lf.triangle_count(), crlf.triangle_count());
    assert_eq!(crlf.textures.len(), 1);
    assert_eq!(crlf.meshes[0].name, "a");
    assert_eq!(lf.materials[0].base_color, crlf.materials[0].base_color);
    assert_eq!(lf.meshes[0].vertices, crlf.meshes[0].vertices);
    // And the binary renders it.
    renders(
        &dir,
        &std::fs::read_to_string(dir.join("scene.obj")).unwrap(),
    );
}

/// A reader of `lines` lines "v 0 0 0", made as they are read: 10^8 of
/// them would be 800 MB. Counts the bytes taken.
struct Lazy {
    block: Vec<u8>,
    pos: usize,
    left: u64,
    given: u64,
}

impl Lazy {
    fn new(lines: u64) -> Lazy {
        Lazy {
            block: b"v 0 0 0\n".repeat(8192),
            pos: 0,
            left: lines * 8,
            given: 0,
        }
    }
}

impl std::io::Read for Lazy {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = {
            let b = self.fill_buf()?;
            let n = b.len().min(buf.len());
            buf[..n].copy_from_slice(&b[..n]);
            n
        };
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for Lazy {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        if self.pos == self.block.len() {
            self.pos = 0;
        }
        let n = ((self.block.len() - self.pos) as u64).min(self.left) as usize;
        Ok(&self.block[self.pos..self.pos + n])
    }
    fn consume(&mut self, amt: usize) {
        self.pos += amt;
        self.given += amt as u64;
        self.left -= amt as u64;
    }
}

/// A file of 10^8 `v` lines (800 MB, made as it is read) is refused once it
/// passes the vertex budget: read no further, allocating no more than the
/// budget's vertices; and the same file on disk (sparse: its lines, then a
/// hole) is refused by the size budget before it is opened.
#[test]
fn a_file_of_10_to_the_8_vertex_lines_is_refused_before_it_is_read_whole() {
    let limits = Limits {
        vertices: 1 << 18,
        ..Limits::DEFAULT
    };
    let options = LoadOptions {
        limits,
        ..Default::default()
    };
    let lazy = Lazy::new(100_000_000);
    let (result, peak) = peak_allocated(|| {
        let mut reader = lazy;
        let r = obj_load::load_reader(Path::new("big.obj"), &mut reader, &options);
        (r.map(|_| ()), reader.given)
    });
    let (result, given) = result;
    let e = format!("{:#}", result.unwrap_err());
    assert!(
        e.contains("big.obj line 262145") && e.contains("more than 262144 vertex positions"),
        "{e}"
    );
    // One line past the budget, and one read-ahead block.
    assert!(given < (262_145 + 8192) * 8, "read {given} bytes");
    assert!(peak < 64 << 20, "allocated {} MiB", peak >> 20);
    // On disk, 800 MB (a hole after the first lines): over a file budget of
    // 256 MiB it is refused before it is opened.
    let dir = temp_dir("obj-huge");
    let path = dir.join("big.obj");
    {
        use std::io::Write as _;
        let mut f = std::fs::File::create(&path).unwrap();
        f.write_all(&b"v 0 0 0\n".repeat(1000)).unwrap();
        f.set_len(800_000_000).unwrap();
    }
    let options = LoadOptions {
        limits: Limits {
            scene_file_bytes: 256 << 20,
            ..Limits::DEFAULT
        },
        ..Default::default()
    };
    let (e, read) =
        common::measure::bytes_read(|| obj_load::load_with(&path, &options).unwrap_err());
    let e = format!("{e:#}");
    assert!(
        e.contains("762.9 MiB, more than the limit of 256 MiB"),
        "{e}"
    );
    assert!(read < 1 << 20, "read {read} bytes");
}

#[test]
fn lines_over_the_line_budget_and_text_that_is_not_utf8() {
    let dir = temp_dir("obj-lines");
    let options = LoadOptions {
        limits: Limits {
            line_bytes: 1000,
            ..Limits::DEFAULT
        },
        ..Default::default()
    };
    let long = format!("v 0 0 0\n# {}\n{QUAD}", "x".repeat(2000));
    let e = obj_load::load_bytes(&dir.join("a.obj"), long.as_bytes(), &options).unwrap_err();
    assert!(
        format!("{e:#}").contains("a.obj line 2: the line is longer than 1000 bytes"),
        "{e:#}"
    );
    // Comments in another encoding are fine; other lines must be UTF-8.
    let mut obj = b"# caf\xe9\n".to_vec();
    obj.extend_from_slice(QUAD.as_bytes());
    assert!(obj_load::load_bytes(&dir.join("a.obj"), &obj, &Default::default()).is_ok());
    let mut obj = QUAD.as_bytes().to_vec();
    obj.extend_from_slice(b"o caf\xe9\n");
    let e = obj_load::load_bytes(&dir.join("a.obj"), &obj, &Default::default()).unwrap_err();
    assert!(
        format!("{e:#}").contains("a.obj line 6: the line is not UTF-8"),
        "{e:#}"
    );
}

/// Statements isr does not render (an `l` line, which a reader could take
/// for a face), colours on some vertices only, degenerate faces; each a
/// render with one warning per kind.
#[test]
fn lines_colours_and_degenerate_faces_render_with_warnings() {
    let dir = temp_dir("obj-warnings");
    let w = renders(
        &dir,
        &format!("{QUAD}v 0 1 0 1 0 0\nl 1 2 5\nf 1 1 2\nf 1 2 2\nf 1 3 5 5\np 1\ncurv 0 1 1 2\nfoo bar\n"),
    );
    for what in [
        "OBJ statements ignored: 'l' (scene.obj line 7; line elements are not rendered)",
        "'p' (scene.obj line 11; point elements",
        "'curv' (scene.obj line 12; free-form geometry",
        "'foo' (scene.obj line 13; it is not part of the OBJ format isr reads)",
        "3 degenerate triangle(s)",
    ] {
        assert!(w.contains(what), "{what}: {w}");
    }
    // Nothing but degenerate faces: an error that says so.
    let e = fails(&dir, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    assert!(
        e.contains("no faces to render (all 1 are degenerate)"),
        "{e}"
    );
    let e = fails(&dir, "# nothing\n");
    assert!(e.contains("no faces to render"), "{e}");
}

/// A texture's rows read the right way up: a 2x2 texture (red, green over
/// blue, white) on a quad whose `vt` put (0, 0) at its corner (0, 0, 0):
/// that corner's quarter of the quad shows blue, the texture's lower left,
/// as OBJ means it (its v grows upward; the GPU's rows start at the top).
#[test]
fn texture_coordinates_put_v_0_at_the_bottom_of_the_texture() {
    let dir = temp_dir("obj-uv");
    std::fs::write(
        dir.join("t.png"),
        png(2, 2, &[255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]),
    )
    .unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl a\nKd 1 1 1\nmap_Kd t.png\n").unwrap();
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3 4/4\n";
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    let mut scene = obj_load::load(&dir.join("scene.obj")).unwrap();
    scene.camera = isr::scene::Camera::look_at(
        glam::Vec3::new(0.5, 1.5, 1.0),
        glam::Vec3::new(0.5, 0.0, -0.5),
        glam::Vec3::Y,
        40f32.to_radians(),
        0.05,
    );
    let gpu = common::gpu();
    let r = common::render(&gpu, &scene, &common::sized("none", 48, 48, 32), 1);
    let at = |x: f32, z: f32| {
        let (px, py) = common::project(&r, glam::Vec3::new(x, 0.0, z)).expect("on screen");
        let a = r.readback.albedo[(py * 48 + px) as usize];
        glam::Vec3::new(a[0], a[1], a[2])
    };
    // The texel centres: u, v = 1/4 and 3/4.
    for ((x, z), (name, want)) in [
        ((0.25, -0.25), ("blue", glam::Vec3::Z)),
        ((0.75, -0.25), ("white", glam::Vec3::ONE)),
        ((0.25, -0.75), ("red", glam::Vec3::X)),
        ((0.75, -0.75), ("green", glam::Vec3::Y)),
    ] {
        let got = at(x, z);
        assert!(
            got.abs_diff_eq(want, 0.1),
            "at ({x}, 0, {z}) the albedo is {got}, not {name}"
        );
    }
}
