//! Property test of the scene loaders on stable Rust (issues 14 and 27):
//! thousands of files generated and mutated from a seed corpus (the Cornell
//! box as glTF and as GLB, small GLBs with sparse accessors, textures and
//! node DAGs; small OBJ files naming MTL libraries and textures, mutated
//! line by line and byte by byte), with a fixed seed. Every input must give a scene whose data is sane or an
//! error, never a panic, a slow load (a hang) or a large allocation; the
//! loader is called without its panic guard (`load_bytes`).
//!
//! Inputs that fail are written to `tests/fuzz-regressions/` (commit them);
//! every file there is replayed first. `ISR_FUZZ_CASES=N` runs N mutated
//! cases instead of the default (`ISR_FUZZ_OBJ_CASES=N` for the OBJ
//! loader); `ISR_FUZZ_SEED=S` changes the seed;
//! `ISR_FUZZ_TRACE=1` writes each input to `target/fuzz-last.*` before it is
//! loaded (to find the input that aborted the process, should one).
mod common;
#[path = "fuzz_loader/mutate.rs"]
mod mutate;

use common::gltf::*;
use common::measure::{peak_allocated, Counting};
use common::temp_dir;
use isr::scene::gltf_load::{load_bytes, LoadOptions};
use isr::scene::limits::Limits;
use isr::scene::obj_load;
use mutate::{mutate_bytes, mutate_json, Rng};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering::Relaxed};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Counts each thread's live bytes and their peak, to catch allocations no
/// budget bounds.
#[global_allocator]
static ALLOC: Counting = Counting;

/// Tight budgets so that what they allow is small and anything else stands out.
const FUZZ_LIMITS: Limits = Limits::FUZZ;
/// More than the budgets above can account for (a few copies of 8 MiB of
/// buffers, 32k vertices, 256k texels).
const MAX_PEAK: usize = 96 << 20;
/// One load taking this long is a hang (they take well under 10 ms): a
/// guard, 300 times a load's time, like the watchdog's 30 s abort.
const SLOW: Duration = Duration::from_secs(3);

/// One fuzz input: bytes and the file name they are loaded as.
#[derive(Clone)]
struct Case {
    name: &'static str,
    bytes: Vec<u8>,
}

/// A 4x4 PNG.
fn small_png() -> Vec<u8> {
    let px: Vec<u8> = (0..4 * 4 * 3).map(|i| (i * 17) as u8).collect();
    png(4, 4, &px)
}

/// The folder inputs are loaded from, with files their URIs may name: a
/// good buffer, a PNG, a directory, a FIFO and a link out of the folder.
fn fixture_dir() -> PathBuf {
    let d = temp_dir("fuzz");
    std::fs::write(d.join("b.bin"), Doc::cornell().bin).unwrap();
    std::fs::write(d.join("t.png"), small_png()).unwrap();
    std::fs::write(d.join("big.png"), png_header_only(4096, 4096)).unwrap();
    std::fs::create_dir_all(d.join("dir")).unwrap();
    // Libraries the OBJ seeds (and their mutations) name.
    for (name, mtl) in OBJ_LIBRARIES {
        std::fs::write(d.join(name), mtl).unwrap();
    }
    #[cfg(unix)]
    {
        let _ = std::process::Command::new("mkfifo")
            .arg(d.join("pipe"))
            .status();
        let _ = std::os::unix::fs::symlink("/etc/passwd", d.join("link"));
    }
    d
}

/// The seed corpus, as JSON documents with their binary chunk (None: .gltf).
fn corpus() -> Vec<(Value, Option<Vec<u8>>)> {
    let mut out = Vec::new();
    let cornell = Doc::cornell();
    out.push((cornell.json.clone(), None));
    // The Cornell box as a GLB.
    out.push((cornell.glb_json(), Some(cornell.bin.clone())));
    // The Cornell box reading its buffer from a file.
    let mut file_doc = cornell.json;
    file_doc["buffers"][0]["uri"] = json!("b.bin");
    out.push((file_doc, None));
    // A triangle GLB, plain and with a sparse POSITION (no base view), with
    // a texture in a buffer view and a TEXCOORD_0.
    let mut tri = Doc::triangle();
    out.push((tri.glb_json(), Some(tri.bin.clone())));
    let idx = tri.view(&[1u8, 2]);
    let val = tri.view(&f32_bytes(&[1., 0., 0., 0., 0., -1.]));
    let uv = tri.floats(&[0., 0., 1., 0., 0., 1.], "VEC2");
    let png = tri.view(&small_png());
    tri.json["accessors"][0] = json!({"componentType": 5126, "count": 3, "type": "VEC3",
        "min": [0, 0, -1], "max": [1, 0, 0],
        "sparse": {"count": 2, "indices": {"bufferView": idx, "componentType": 5121},
                   "values": {"bufferView": val}}});
    let t = &mut tri.json;
    t["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv);
    t["meshes"][0]["primitives"][0]["material"] = json!(0);
    t["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    t["textures"] = json!([{"source": 0, "sampler": 0}]);
    t["samplers"] = json!([{}]);
    t["images"] = json!([{"bufferView": png, "mimeType": "image/png"}]);
    out.push((tri.glb_json(), Some(tri.bin.clone())));
    // The same with the image from a file and the buffer embedded.
    let mut tri_file = tri.embedded();
    tri_file["images"] = json!([{"uri": "t.png"}]);
    out.push((tri_file, None));
    // A small node DAG.
    out.push((node_dag(6), None));
    out
}

/// MTL libraries in the fixture folder: good, naming a missing texture, a
/// FIFO, a directory, a link out, a too-large header, naming itself, broken.
const OBJ_LIBRARIES: &[(&str, &str)] = &[
    (
        "m.mtl",
        "newmtl a\nKd 0.5 0.6 0.7\nmap_Kd t.png\nnewmtl b\nKd 1 0 0\nNs 10\n",
    ),
    ("gone.mtl", "newmtl a\nmap_Kd gone.png\n"),
    ("pipe.mtl", "newmtl a\nmap_Kd pipe\n"),
    ("dir.mtl", "newmtl a\nmap_Kd dir\n"),
    ("link.mtl", "newmtl a\nmap_Kd link\n"),
    ("big.mtl", "newmtl a\nmap_Kd big.png\n"),
    ("self.mtl", "mtllib self.mtl\nnewmtl a\nKd 0.2 0.2 0.2\n"),
    (
        "broken.mtl",
        "newmtl a\nKd 0.5\nKd 1 2\nmap_Kd -s 1 1\n\u{0}\n",
    ),
];

/// OBJ seeds: a textured quad, polygons and relative indices, normals,
/// several objects and materials.
fn obj_corpus() -> Vec<String> {
    vec![
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3 4/4\n".into(),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 1.5 0\nv 0 1 0\nf -5 -4 -3 -2 -1\no second\nv 0 0 1\nv 1 0 1\nv 1 1 1\nf 6 7 8\n".into(),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nvn 1 0 0\nusemtl b\nf 1//1 2//1 3//1\nusemtl a\nf 1//2 3//2 4//2\ng other\nusemtl missing\nf 2 3 4\n".into(),
        "# crlf\r\nmtllib self.mtl\r\nv 0 0 0 1\r\nv 1 0 0 0.5\r\nv 0 1 0 1 0 0\r\ns 1\r\nl 1 2\r\nf 1 2 3\r\n".into(),
    ]
}

/// A line-level change to an OBJ: a line dropped, repeated or cut, a
/// number or index replaced by a hostile one, a statement inserted.
fn mutate_obj(text: &mut String, rng: &mut Rng) {
    let mut lines: Vec<String> = text.split('\n').map(str::to_string).collect();
    let n = lines.len().max(1);
    let k = rng.below(n);
    const NUMBERS: &[&str] = &[
        "0",
        "-1",
        "-9",
        "9",
        "1e39",
        "-1e39",
        "nan",
        "inf",
        "1e30",
        "1e-30",
        "4294967296",
        "-2147483649",
        "99999999999999999999",
        "0x10",
        "",
        "1/",
        "/1",
        "1//",
        "1/2/3/4",
        "+3",
    ];
    const LINES: &[&str] = &[
        "mtllib m.mtl",
        "mtllib gone.mtl",
        "mtllib pipe.mtl",
        "mtllib dir.mtl",
        "mtllib link.mtl",
        "mtllib big.mtl",
        "mtllib self.mtl",
        "mtllib broken.mtl",
        "mtllib ../m.mtl",
        "mtllib /etc/passwd",
        "mtllib fuzz.obj",
        "mtllib dir",
        "mtllib pipe",
        "mtllib",
        "usemtl a",
        "usemtl",
        "usemtl b",
        "o",
        "g a b",
        "s off",
        "vt 0.5",
        "vn 0 0 0",
        "v 1 2 3 4 5",
        "f 1 1 1",
        "f 1 2",
        "f",
        "l 1 2 3",
        "p 1",
        "curv 0 1 1 2",
        "vp 0.5",
        "\u{0}",
        "\r",
        "f 1/1/1 2/2/2 3/3/3",
    ];
    match rng.below(7) {
        0 if lines.len() > 1 => {
            lines.remove(k);
        }
        1 => {
            let l = lines[k].clone();
            lines.insert(k, l);
        }
        2 => {
            let l = &mut lines[k];
            let cut = rng.below(l.len() + 1);
            if l.is_char_boundary(cut) {
                l.truncate(cut);
            }
        }
        3 | 4 => {
            let words: Vec<String> = lines[k].split(' ').map(str::to_string).collect();
            if words.len() > 1 {
                let mut words = words;
                let w = 1 + rng.below(words.len() - 1);
                words[w] = rng.pick(NUMBERS).to_string();
                lines[k] = words.join(" ");
            }
        }
        5 => lines.insert(k, rng.pick(LINES).to_string()),
        _ => {
            // A long face, fanned.
            let m = 3 + rng.below(200);
            let face: Vec<String> = (0..m).map(|i| format!("{}", 1 + i % 4)).collect();
            lines.insert(k, format!("f {}", face.join(" ")));
        }
    }
    *text = lines.join("\n");
}

fn to_case(doc: &Value, bin: Option<&[u8]>) -> Case {
    match bin {
        Some(b) => Case {
            name: "fuzz.glb",
            bytes: glb(doc, Some(b)),
        },
        None => Case {
            name: "fuzz.gltf",
            bytes: serde_json::to_vec(doc).unwrap(),
        },
    }
}

static PANIC_MESSAGE: Mutex<String> = Mutex::new(String::new());

/// What went wrong with one input, if anything; else the loader's error
/// (None: it gave a scene).
fn check(dir: &Path, case: &Case) -> Result<Option<String>, String> {
    let options = LoadOptions {
        allow_outside_uris: false,
        limits: FUZZ_LIMITS,
    };
    let path = dir.join(case.name);
    let started = Instant::now();
    let (result, peak) = peak_allocated(|| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let loaded = if case.name.ends_with(".obj") {
                obj_load::load_bytes(&path, &case.bytes, &options)
            } else {
                load_bytes(&path, &case.bytes, &options)
            };
            loaded.map(|s| {
                // What the renderer does first with a scene.
                let bounds = s.bounds();
                let state = s.rest_state();
                (s, bounds, state)
            })
        }))
    });
    let took = started.elapsed();
    let problem = match &result {
        Err(_) => Some(format!(
            "panic: {}",
            PANIC_MESSAGE.lock().map(|m| m.clone()).unwrap_or_default()
        )),
        Ok(Err(e)) => {
            let msg = format!("{e:#}");
            (msg.is_empty() || msg.contains("root:x:"))
                .then(|| format!("unclear or leaking error: {msg}"))
        }
        Ok(Ok((s, bounds, state))) => sane(s, *bounds, state),
    };
    if let Some(p) = problem {
        return Err(p);
    }
    if took > SLOW {
        return Err(format!("took {took:?}"));
    }
    if peak > MAX_PEAK {
        return Err(format!("allocated {} MiB at peak", peak >> 20));
    }
    Ok(match result {
        Ok(Err(e)) => Some(format!("{e:#}")),
        _ => None,
    })
}

/// A loaded scene holds only what the renderer can take.
fn sane(
    s: &isr::scene::Scene,
    bounds: Option<(glam::Vec3, glam::Vec3)>,
    state: &isr::scene::FrameState,
) -> Option<String> {
    if s.instances.is_empty() || bounds.is_none() {
        return Some("a scene without geometry".into());
    }
    for m in &s.meshes {
        let n = m.vertices.len();
        if m.indices.iter().any(|&i| i as usize >= n) || m.indices.len() % 3 != 0 {
            return Some(format!("mesh {} has bad indices", m.name));
        }
        if m.material >= s.materials.len() {
            return Some(format!("mesh {} has a bad material", m.name));
        }
        let finite = |a: &[f32]| a.iter().all(|c| c.is_finite());
        if !m
            .vertices
            .iter()
            .all(|v| finite(&v.position) && finite(&v.normal) && finite(&v.uv))
        {
            return Some(format!("mesh {} has non-finite vertices", m.name));
        }
    }
    if s.instances.iter().any(|i| i.mesh >= s.meshes.len()) {
        return Some("an instance of a missing mesh".into());
    }
    if s.materials
        .iter()
        .any(|m| m.texture.is_some_and(|t| t >= s.textures.len()))
    {
        return Some("a material with a missing texture".into());
    }
    if s.textures
        .iter()
        .any(|t| t.rgba8.len() != t.width as usize * t.height as usize * 4)
    {
        return Some("a texture whose size does not match its pixels".into());
    }
    let l = &state.lights[0];
    let c = &state.camera;
    if !(l.position.is_finite()
        && l.direction.is_finite()
        && l.color.is_finite()
        && l.intensity.is_finite()
        && l.intensity >= 0.0
        && l.color.min_element() >= 0.0
        && c.world_from_camera.is_finite()
        && c.znear > 0.0
        && c.yfov > 0.0
        && c.yfov < std::f32::consts::PI)
    {
        return Some(format!("a degenerate light or camera: {l:?} {c:?}"));
    }
    None
}

fn regressions_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz-regressions")
}

/// Keeps a failing input as a regression test.
fn save(case: &Case, problem: &str) -> PathBuf {
    let hash = case.bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    });
    let ext = Path::new(case.name).extension().unwrap().to_str().unwrap();
    let dir = regressions_dir();
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("{hash:016x}.{ext}"));
    std::fs::write(&p, &case.bytes).unwrap();
    std::fs::write(p.with_extension(format!("{ext}.txt")), problem).unwrap();
    p
}

/// Aborts the process, keeping the input, when one load hangs: a hang
/// inside the loader cannot be interrupted from the test's own thread.
fn watchdog(current: &'static Mutex<Option<Case>>, started_ms: &'static AtomicU64) {
    static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    let epoch = *EPOCH.get_or_init(Instant::now);
    std::thread::spawn(move || loop {
        std::thread::sleep(Duration::from_millis(200));
        let since = started_ms.load(Relaxed);
        if since == u64::MAX {
            continue;
        }
        let now = epoch.elapsed().as_millis() as u64;
        if now.saturating_sub(since) > 30_000 {
            if let Some(case) = current.lock().ok().and_then(|c| c.clone()) {
                let p = save(&case, "hang: a load ran for more than 30 s");
                eprintln!("fuzz_loader: a load hangs; input kept as {}", p.display());
            }
            std::process::abort();
        }
    });
}

#[test]
fn loader_never_panics_hangs_or_allocates_without_bound() {
    static CURRENT: Mutex<Option<Case>> = Mutex::new(None);
    static STARTED_MS: AtomicU64 = AtomicU64::new(u64::MAX);
    static HOOKED: AtomicBool = AtomicBool::new(false);
    if !HOOKED.swap(true, Relaxed) {
        // Panics inside a load are recorded with their input; the test's own
        // assertions print as usual.
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if STARTED_MS.load(Relaxed) == u64::MAX {
                return default(info);
            }
            if let Ok(mut m) = PANIC_MESSAGE.lock() {
                *m = info.to_string();
            }
        }));
    }
    let epoch = Instant::now();
    watchdog(&CURRENT, &STARTED_MS);
    let dir = fixture_dir();
    let trace = std::env::var_os("ISR_FUZZ_TRACE").is_some();
    let trace_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target");
    let mut failures = Vec::new();
    // Some(the loader's error or None for a scene), None: the input failed.
    let run = |case: Case, keep: bool, failures: &mut Vec<String>| -> Option<Option<String>> {
        if trace {
            let ext = Path::new(case.name).extension().unwrap().to_str().unwrap();
            let _ = std::fs::write(trace_dir.join(format!("fuzz-last.{ext}")), &case.bytes);
        }
        *CURRENT.lock().unwrap() = Some(case.clone());
        STARTED_MS.store(epoch.elapsed().as_millis() as u64, Relaxed);
        let problem = check(&dir, &case);
        STARTED_MS.store(u64::MAX, Relaxed);
        match problem {
            Ok(error) => Some(error),
            Err(p) => {
                let kept = if keep {
                    format!(" (kept as {})", save(&case, &p).display())
                } else {
                    String::new()
                };
                failures.push(format!("{}{kept}: {p}", case.name));
                None
            }
        }
    };

    // Every input that ever failed, first.
    let mut replayed = 0;
    if let Ok(entries) = std::fs::read_dir(regressions_dir()) {
        let mut files: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
        files.sort();
        for p in files {
            let name = match p.extension().and_then(|e| e.to_str()) {
                Some("gltf") => "fuzz.gltf",
                Some("glb") => "fuzz.glb",
                Some("obj") => "fuzz.obj",
                _ => continue,
            };
            let bytes = std::fs::read(&p).unwrap();
            if run(Case { name, bytes }, false, &mut failures).is_none() {
                let last = failures.pop().unwrap();
                failures.push(format!("regression {}: {last}", p.display()));
            }
            replayed += 1;
        }
    }

    let seed: u64 = std::env::var("ISR_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x15_2009);
    let cases: usize = std::env::var("ISR_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(40_000);
    let mut rng = Rng(seed);
    let seeds = corpus();
    // The seeds themselves load.
    for (doc, bin) in &seeds {
        let case = to_case(doc, bin.as_deref());
        let options = LoadOptions {
            limits: FUZZ_LIMITS,
            ..Default::default()
        };
        if let Err(e) = load_bytes(&dir.join(case.name), &case.bytes, &options) {
            panic!("a seed does not load: {e:#}");
        }
    }
    let mut scenes = 0usize;
    let mut messages = std::collections::HashMap::new();
    for i in 0..cases {
        let (doc, bin) = rng.pick(&seeds).clone();
        let mut doc = doc;
        let mut bin = bin;
        let structural = 1 + rng.below(2);
        for _ in 0..structural {
            mutate_json(&mut doc, &mut rng);
        }
        if let Some(b) = bin.as_mut() {
            if rng.chance(0.3) {
                for _ in 0..1 + rng.below(4) {
                    let n = b.len();
                    if n > 0 {
                        let k = rng.below(n);
                        b[k] = rng.next() as u8;
                    }
                }
            }
        }
        let mut case = to_case(&doc, bin.as_deref());
        // A quarter of the cases also get byte-level damage (mostly parse
        // errors for JSON, header and chunk damage for GLB).
        if i % 4 == 0 {
            for _ in 0..1 + rng.below(3) {
                mutate_bytes(&mut case.bytes, &mut rng);
            }
        }
        // Sometimes a .glb name on JSON and the other way round.
        if rng.chance(0.05) {
            case.name = if case.name == "fuzz.glb" {
                "fuzz.gltf"
            } else {
                "fuzz.glb"
            };
        }
        match run(case, true, &mut failures) {
            Some(None) => scenes += 1,
            Some(Some(e)) => {
                // The message without the file's path, cut before details.
                let e = e.split(": ").skip(1).take(2).collect::<Vec<_>>().join(": ");
                let key: String = e.chars().take(60).collect();
                *messages.entry(key).or_insert(0usize) += 1;
            }
            None => {}
        }
        if failures.len() > 20 {
            break;
        }
    }
    // The OBJ loader: its seeds load, then mutated cases.
    let obj_seeds = obj_corpus();
    for seed in &obj_seeds {
        let options = LoadOptions {
            limits: FUZZ_LIMITS,
            ..Default::default()
        };
        if let Err(e) = obj_load::load_bytes(&dir.join("fuzz.obj"), seed.as_bytes(), &options) {
            panic!("an OBJ seed does not load: {e:#}\n{seed}");
        }
    }
    let obj_cases: usize = std::env::var("ISR_FUZZ_OBJ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000);
    let mut obj_scenes = 0usize;
    for i in 0..obj_cases {
        let mut text = rng.pick(&obj_seeds).clone();
        for _ in 0..1 + rng.below(4) {
            mutate_obj(&mut text, &mut rng);
        }
        let mut bytes = text.into_bytes();
        if i % 4 == 0 {
            mutate_bytes(&mut bytes, &mut rng);
        }
        let case = Case {
            name: "fuzz.obj",
            bytes,
        };
        match run(case, true, &mut failures) {
            Some(None) => obj_scenes += 1,
            Some(Some(e)) => {
                let e = e.split(": ").skip(1).take(2).collect::<Vec<_>>().join(": ");
                let key: String = e.chars().take(60).collect();
                *messages.entry(format!("obj: {key}")).or_insert(0usize) += 1;
            }
            None => {}
        }
        if failures.len() > 20 {
            break;
        }
    }
    println!("fuzz_loader: {obj_cases} mutated OBJ cases, {obj_scenes} of them scenes");
    let mut common: Vec<_> = messages.into_iter().collect();
    common.sort_by_key(|c| std::cmp::Reverse(c.1));
    for (m, n) in common.iter().take(15) {
        println!("{n:6}  {m}");
    }
    println!(
        "fuzz_loader: {replayed} regressions replayed; {cases} mutated cases, {scenes} of them scenes, the rest errors; {:.1} s",
        epoch.elapsed().as_secs_f64()
    );
    assert!(
        failures.is_empty(),
        "{} inputs failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    // The mutations must reach past the parser often enough to mean something.
    assert!(scenes * 20 > cases, "only {scenes} of {cases} cases loaded");
}
