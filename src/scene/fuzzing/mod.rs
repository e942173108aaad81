//! Generators of hostile OBJ, MTL and scene-description files, and the
//! properties every load of them must have. One set for both fuzzers: the
//! `cargo fuzz` targets (`fuzz/fuzz_targets/obj_loader.rs`,
//! `description.rs`, nightly) drive them with libFuzzer's bytes; the stable
//! property test (`tests/fuzz_loader_obj.rs`, run by `cargo test`) with a
//! seeded generator's. A case is a pure function of its bytes, so an input
//! either fuzzer finds failing is replayed by the other (keep it in
//! `tests/fuzz-regressions/` as `NAME.objgen` or `NAME.descgen`).
//!
//! The files are small and built from what the hostile pass found: numbers
//! at f32's ends (1e-45, 3e38, 1e39, NaN), indices of 0, past the end or
//! negative, zero and huge normals, names with escape sequences, NULs and
//! invalid UTF-8, a byte-order mark, CR and CRLF line ends, libraries named
//! again and again, material switches, unknown keys, corrupt textures,
//! orbits and cameras out of range; the budgets are `Limits::FUZZ`.

use std::path::{Path, PathBuf};

mod check;
pub use check::{check_message, check_scene};

/// The bytes a case is made from, taken in order; past their end, zeros
/// (so any input, even empty, makes a case).
pub struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Bytes<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Self { data, pos: 0 }
    }

    fn byte(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }

    /// A number below `n` (at most 65,536), from one or two bytes.
    fn below(&mut self, n: usize) -> usize {
        let x = if n > 256 {
            (self.byte() as usize) << 8 | self.byte() as usize
        } else {
            self.byte() as usize
        };
        x % n.max(1)
    }

    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.below(items.len())]
    }

    /// True `n` times in 256; false once the bytes are used up (so a
    /// short input makes a plain case).
    fn chance(&mut self, n: u8) -> bool {
        self.more() && self.byte() < n
    }

    /// Whether any bytes are left.
    fn more(&self) -> bool {
        self.pos < self.data.len()
    }
}

/// One case: the scene file's name and bytes, and the files beside it.
#[derive(Clone, Debug)]
pub struct Case {
    pub name: &'static str,
    pub bytes: Vec<u8>,
    pub files: Vec<(&'static str, Vec<u8>)>,
}

impl Case {
    /// Writes the files beside the scene into `dir` (which holds
    /// [`fixtures`]); returns where the scene file is, as if read from there.
    pub fn write(&self, dir: &Path) -> std::io::Result<PathBuf> {
        for (name, bytes) in &self.files {
            // A new file, not one truncated and written again: ext4 flushes
            // a truncated file's data when it is closed (auto_da_alloc),
            // which made thousands of cases wait on the disk.
            let path = dir.join(name);
            let _ = std::fs::remove_file(&path);
            std::fs::write(path, bytes)?;
        }
        Ok(dir.join(self.name))
    }
}

/// Numbers as a file writes them: ordinary ones, and (one time in eight)
/// ones at f32's ends or not numbers at all.
const NUMBERS: &[&str] = &["0", "1", "-1", "0.5", "2", "-0.25", "0.125", "3"];
const HOSTILE_NUMBERS: &[&str] = &[
    "1e-30", "1e30", "3e38", "-3e38", "1e39", "1e-45", "nan", "inf", "-inf", "9e5", "65536",
    "65537", "1e", "x", "", "0x10", "+3", "1,5",
];

/// Face-corner indices: in range and relative, and (one time in eight)
/// 0, past the end or not numbers.
const INDICES: &[&str] = &["1", "2", "3", "4", "-1", "-2", "-3", "-4"];
const HOSTILE_INDICES: &[&str] = &["0", "-9", "9", "99999999999999999999", "", "x"];

/// Names: plain, repeated, hostile to a terminal, long.
const NAMES: &[&str] = &[
    "a",
    "b",
    "missing",
    "\u{1b}[2J",
    "\u{7}",
    "na\u{0}me",
    "\u{202e}txt",
    "a b",
    "\u{feff}a",
];

/// Library names: the good one, itself, the OBJ, missing, outside, a
/// folder, a FIFO, a link out.
const LIBRARIES: &[&str] = &[
    "m.mtl",
    "m.mtl",
    "self.mtl",
    "scene.obj",
    "missing.mtl",
    "../m.mtl",
    "/etc/passwd",
    "dir",
    "pipe",
    "link",
    "m.mtl m.mtl m.mtl",
];

/// Texture names: good, corrupt, missing, a folder, outside.
const TEXTURES: &[&str] = &[
    "t.png",
    "t.png",
    "bad.png",
    "missing.png",
    "dir",
    "../t.png",
    "link",
];

/// The files every case may name, written once into `dir`: a 2x2 PNG, one
/// whose header checksum is wrong, a library that names itself, a folder,
/// a FIFO and a link to /etc/passwd.
pub fn fixtures(dir: &Path) -> std::io::Result<()> {
    let png = png_2x2();
    let mut bad = png.clone();
    bad[29] ^= 0x5a;
    std::fs::write(dir.join("t.png"), &png)?;
    std::fs::write(dir.join("bad.png"), &bad)?;
    std::fs::write(
        dir.join("self.mtl"),
        "mtllib self.mtl\nnewmtl a\nKd 0.2 0.3 0.4\n",
    )?;
    std::fs::create_dir_all(dir.join("dir"))?;
    #[cfg(unix)]
    {
        let _ = std::process::Command::new("mkfifo")
            .arg(dir.join("pipe"))
            .status();
        let _ = std::os::unix::fs::symlink("/etc/passwd", dir.join("link"));
    }
    Ok(())
}

/// A 2x2 RGB PNG, written by hand (stored, uncompressed deflate).
fn png_2x2() -> Vec<u8> {
    fn crc(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    fn adler(bytes: &[u8]) -> u32 {
        let (mut a, mut b) = (1u32, 0u32);
        for &x in bytes {
            a = (a + x as u32) % 65521;
            b = (b + a) % 65521;
        }
        b << 16 | a
    }
    let raw = [0u8, 255, 0, 0, 0, 255, 0, 0, 0, 0, 255, 255, 255, 255];
    let mut z = vec![0x78, 0x01, 1, raw.len() as u8, 0, !(raw.len() as u8), 0xff];
    z.extend_from_slice(&raw);
    z.extend_from_slice(&adler(&raw).to_be_bytes());
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    for (kind, data) in [
        (&b"IHDR"[..], vec![0, 0, 0, 2, 0, 0, 0, 2, 8, 2, 0, 0, 0]),
        (b"IDAT", z),
        (b"IEND", vec![]),
    ] {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut chunk = kind.to_vec();
        chunk.extend_from_slice(&data);
        out.extend_from_slice(&chunk);
        out.extend_from_slice(&crc(&chunk).to_be_bytes());
    }
    out
}

/// One of `usual`, or one time in eight one of `hostile` (what makes a
/// case an error: a case of many lines must still load often).
fn rare<T: Copy>(b: &mut Bytes, usual: &[T], hostile: &[T]) -> T {
    if b.chance(32) {
        b.pick(hostile)
    } else {
        b.pick(usual)
    }
}

/// `n` numbers.
fn numbers(b: &mut Bytes, n: usize) -> String {
    (0..n)
        .map(|_| {
            if b.chance(32) {
                b.pick(HOSTILE_NUMBERS)
            } else {
                b.pick(NUMBERS)
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// A face-corner index.
fn index(b: &mut Bytes) -> &'static str {
    if b.chance(32) {
        b.pick(HOSTILE_INDICES)
    } else {
        b.pick(INDICES)
    }
}

/// A line of an OBJ file.
fn obj_line(b: &mut Bytes) -> String {
    match b.below(16) {
        0..=2 => {
            let n = 3 + rare(b, &[0, 0, 1, 3], &[4, 2, 0]);
            format!("v {}", numbers(b, n))
        }
        3 => {
            let n = rare(b, &[2, 2, 1, 3], &[0, 4]);
            format!("vt {}", numbers(b, n))
        }
        4 => match b.below(3) {
            0 => format!(
                "vn {}",
                b.pick(&["0 0 0", "0 1e-30 0", "0 1e30 0", "1e-45 0 0"])
            ),
            _ => format!("vn {}", numbers(b, 3)),
        },
        5..=8 => {
            let corners = rare(b, &[3, 3, 4, 5, 8, 40], &[2, 0]);
            let form = b.below(4);
            let mut f = String::from("f");
            for _ in 0..corners {
                let (v, t, n) = (index(b), index(b), index(b));
                f += &match form {
                    0 => format!(" {v}"),
                    1 => format!(" {v}/{t}"),
                    2 => format!(" {v}//{n}"),
                    _ => format!(" {v}/{t}/{n}"),
                };
            }
            f
        }
        9 => format!("usemtl {}", b.pick(NAMES)),
        10 => format!(
            "mtllib {}",
            rare(b, &["m.mtl", "m.mtl m.mtl m.mtl"], LIBRARIES)
        ),
        11 => format!(
            "{} {}",
            b.pick(&["g", "o", "s", "l 1 2", "p", "curv", "mg"]),
            b.pick(NAMES)
        ),
        12 => format!("{} 1", b.pick(NAMES)),
        13 => "# comment \u{1b}[2J \u{0}".into(),
        14 => String::new(),
        _ if b.chance(64) => {
            String::from_utf8_lossy(&[b'v', b' ', b.byte(), b' ', b.byte(), b' ', b.byte()])
                .into_owned()
        }
        _ => "g".into(),
    }
}

/// A line of an MTL file.
fn mtl_line(b: &mut Bytes) -> String {
    match b.below(8) {
        0 | 1 => format!("newmtl {}", b.pick(NAMES)),
        2 | 3 => {
            let n = rare(b, &[3, 3, 1], &[2, 4]);
            let hostile = numbers(b, n);
            let values = rare(b, &["0.5 0.2 1", "2 0.5 0.5", "0.3"], &[hostile.as_str()]);
            format!("Kd {values}")
        }
        4 => {
            let options = b.pick(&["", "-s 2 2 1 ", "-o 1 ", "-clamp on ", "-mm 0 1 ", "-bm "]);
            format!("map_Kd {options}{}", rare(b, &["t.png"], TEXTURES))
        }
        5 => format!(
            "{} 1",
            b.pick(&["Ns", "illum", "d", "\u{1b}]0;x\u{7}", "mtllib"])
        ),
        6 => "newmtl a".into(),
        _ => String::new(),
    }
}

/// Lines joined by the case's line end, with a byte-order mark maybe.
fn text(b: &mut Bytes, lines: &[String]) -> Vec<u8> {
    let end = b.pick(&["\n", "\n", "\r\n", "\r"]);
    let mut s = if b.chance(32) {
        "\u{feff}".to_string()
    } else {
        String::new()
    };
    for l in lines {
        s += l;
        s += end;
    }
    s.into_bytes()
}

/// A line repeated: what the warnings and the material merge met a
/// million times, a thousand times here.
fn repeated(b: &mut Bytes, line: String) -> Vec<String> {
    let n = if b.chance(16) { 1000 } else { 1 };
    vec![line; n]
}

/// An OBJ case: the OBJ, and its library `m.mtl`.
pub fn obj_case(b: &mut Bytes) -> Case {
    // A quad to start from, most of the time, so that faces have vertices.
    let mut lines: Vec<String> = if b.chance(200) {
        [
            "mtllib m.mtl",
            "v 0 0 0",
            "v 1 0 0",
            "v 1 0 -1",
            "v 0 0 -1",
            "vt 0 0",
            "vt 1 1",
            "vn 0 1 0",
            "usemtl a",
            "f 1/1/1 2/2/1 3/2/1 4/1/1",
        ]
        .map(String::from)
        .to_vec()
    } else {
        Vec::new()
    };
    let n = 1 + b.below(24);
    for _ in 0..n {
        if !b.more() && !lines.is_empty() {
            break;
        }
        let line = obj_line(b);
        // Mostly at the end, so that faces follow the vertices they name.
        let at = if b.chance(64) {
            b.below(lines.len() + 1)
        } else {
            lines.len()
        };
        for l in repeated(b, line) {
            lines.insert(at, l);
        }
    }
    let mut mtl: Vec<String> = vec![
        "newmtl a".into(),
        "Kd 0.5 0.6 0.7".into(),
        "map_Kd t.png".into(),
    ];
    for _ in 0..b.below(8) {
        let line = mtl_line(b);
        mtl.extend(repeated(b, line));
    }
    let obj = text(b, &lines);
    let mtl = text(b, &mtl);
    Case {
        name: "scene.obj",
        files: vec![("scene.obj", obj.clone()), ("m.mtl", mtl)],
        bytes: obj,
    }
}

/// A place or direction as JSON: small numbers, or one time in eight per
/// coordinate one at f32's ends or past the coordinate budget.
fn vector(b: &mut Bytes) -> serde_json::Value {
    const USUAL: &[f64] = &[0.0, 1.0, -1.0, 0.5, 2.0, -0.3];
    const HOSTILE: &[f64] = &[1e-30, 1e30, -1e30, 9e5, -9e5, 1e7, 3e38, 1e-45];
    serde_json::json!([
        rare(b, USUAL, HOSTILE),
        rare(b, USUAL, HOSTILE),
        rare(b, USUAL, HOSTILE)
    ])
}

/// A light of a description.
fn light(b: &mut Bytes) -> serde_json::Value {
    let kind = rare(
        b,
        &["spot", "point", "directional"],
        &["laser", "\u{1b}[2J"],
    );
    let mut l = serde_json::json!({ "type": kind });
    for key in ["position", "target", "direction", "color"] {
        if b.chance(160) {
            l[key] = vector(b);
        }
    }
    for (key, usual, hostile) in [
        ("intensity", &[1.0, 5.0][..], &[0.0, -1.0, 1e30, 1e-45][..]),
        ("cone", &[40.0, 60.0], &[90.0, 95.0, 0.0]),
        ("range", &[10.0], &[0.0, -1.0, 1e30]),
    ] {
        if b.chance(60) {
            l[key] = serde_json::json!(rare(b, usual, hostile));
        }
    }
    motion(b, &mut l);
    l
}

/// A path or an orbit, maybe.
fn motion(b: &mut Bytes, x: &mut serde_json::Value) {
    match b.below(4) {
        0 => {
            let keys: Vec<serde_json::Value> = (0..b.below(4))
                .map(|k| {
                    let t = k as f64 * rare(b, &[1.0], &[-1.0, 0.0]);
                    serde_json::json!({"t": t, "position": vector(b)})
                })
                .collect();
            x["path"] = serde_json::json!(keys);
        }
        1 => {
            x["orbit"] = serde_json::json!({
                "period": rare(b, &[4.0], &[0.0, -1.0, 1e30]),
                "center": vector(b),
                "turns": rare(b, &[1.0, 0.5], &[1000.0, 1001.0, 0.0]),
            })
        }
        _ => {}
    }
}

/// A description case: the description, its OBJ (a quad, or half the
/// time a generated one) and its library.
pub fn description_case(b: &mut Bytes) -> Case {
    let obj = if b.chance(128) {
        obj_case(b)
    } else {
        let quad = b"v 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nf 1 2 3 4\n".to_vec();
        Case {
            name: "scene.obj",
            bytes: quad.clone(),
            files: vec![("scene.obj", quad)],
        }
    };
    let mesh = rare(
        b,
        &["scene.obj"],
        &[
            "missing.obj",
            "../scene.obj",
            "\u{1b}[2J.obj",
            "d.scene.json",
        ],
    );
    let mut d = serde_json::json!({ "mesh": mesh });
    if b.chance(60) {
        d["scale"] = serde_json::json!(rare(b, &[1.0, 2.0, 0.5], &[0.0, -1.0, 1e-30, 1e30, 1e-7]));
    }
    if b.chance(40) {
        d["up"] = serde_json::json!(rare(b, &["+z", "-x", "+y"], &["sideways", "\u{1b}[2J"]));
    }
    if b.chance(40) {
        let size = serde_json::json!([2.0, rare(b, &[3.0], &[0.0, 1e30]), 2.0]);
        d["room"] = serde_json::json!({"size": size, "albedo": rare(b, &[0.5], &[2.0, -1.0])});
    }
    let lights: Vec<serde_json::Value> = (0..b.below(3)).map(|_| light(b)).collect();
    if !lights.is_empty() {
        d["lights"] = serde_json::json!(lights);
    }
    if b.chance(160) {
        let mut c = serde_json::json!({"position": vector(b)});
        if b.chance(128) {
            c["target"] = vector(b);
        }
        if b.chance(128) {
            let fov = rare(
                b,
                &[45.0, 60.0, 1.2e-4, 179.9999],
                &[1e-40, 1e-20, 180.0, 0.0],
            );
            c["fov"] = serde_json::json!(fov);
        }
        if b.chance(64) {
            c["znear"] = serde_json::json!(rare(b, &[0.01], &[0.0, -1.0, 1e-45, 1e30]));
        }
        motion(b, &mut c);
        d["camera"] = c;
    }
    if b.chance(16) {
        d["\u{1b}[2J"] = serde_json::json!(1);
    }
    let mut bytes = serde_json::to_vec(&d).unwrap_or_default();
    if b.chance(32) {
        bytes.splice(0..0, *b"\xEF\xBB\xBF");
    }
    if b.chance(16) && !bytes.is_empty() {
        let k = b.below(bytes.len());
        bytes[k] = b.byte();
    }
    let mut files = obj.files;
    files.push(("d.scene.json", bytes.clone()));
    Case {
        name: "d.scene.json",
        bytes,
        files,
    }
}
