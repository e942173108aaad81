//! Property test of the scene loader on stable Rust (issue 14): thousands of
//! files generated and mutated from a seed corpus (the Cornell box as glTF
//! and as GLB, small GLBs with sparse accessors, textures and node DAGs),
//! with a fixed seed. Every input must give a scene whose data is sane or an
//! error, never a panic, a slow load (a hang) or a large allocation; the
//! loader is called without its panic guard (`load_bytes`).
//!
//! Inputs that fail are written to `tests/fuzz-regressions/` (commit them);
//! every file there is replayed first. `ISR_FUZZ_CASES=N` runs N mutated
//! cases instead of the default; `ISR_FUZZ_SEED=S` changes the seed;
//! `ISR_FUZZ_TRACE=1` writes each input to `target/fuzz-last.*` before it is
//! loaded (to find the input that aborted the process, should one).
#[path = "support/gltf.rs"]
mod gltf;

use gltf::*;
use isr::scene::gltf_load::{load_bytes, LoadOptions};
use isr::scene::limits::Limits;
use serde_json::{json, Value};
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering::Relaxed};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Counts live bytes and their peak, to catch allocations no budget bounds.
struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let live = LIVE.fetch_add(l.size(), Relaxed) + l.size();
            PEAK.fetch_max(live, Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        LIVE.fetch_sub(l.size(), Relaxed);
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, l, new) };
        if !q.is_null() {
            if new >= l.size() {
                let live = LIVE.fetch_add(new - l.size(), Relaxed) + new - l.size();
                PEAK.fetch_max(live, Relaxed);
            } else {
                LIVE.fetch_sub(l.size() - new, Relaxed);
            }
        }
        q
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// Tight budgets so that what they allow is small and anything else stands out.
const FUZZ_LIMITS: Limits = Limits {
    scene_file_bytes: 8 << 20,
    buffer_bytes: 8 << 20,
    image_file_bytes: 1 << 20,
    texture_dimension: 1024,
    texture_pixels: 1 << 18,
    node_visits: 1 << 12,
    hierarchy_depth: 64,
    triangles: 1 << 15,
    vertices: 1 << 15,
    coordinate: 1e6,
};
/// More than the budgets above can account for (a few copies of 8 MiB of
/// buffers, 32k vertices, 256k texels).
const MAX_PEAK: usize = 96 << 20;
/// One load taking this long is a hang (they take well under 10 ms).
const SLOW: Duration = Duration::from_secs(3);

/// SplitMix64: small, deterministic, good enough to pick mutations.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
    fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.below(v.len())]
    }
}

/// One fuzz input: bytes and the file name they are loaded as.
#[derive(Clone)]
struct Case {
    name: &'static str,
    bytes: Vec<u8>,
}

/// The folder inputs are loaded from, with files their URIs may name: a
/// good buffer, a PNG, a directory, a FIFO and a link out of the folder.
fn fixture_dir() -> PathBuf {
    let d = temp_dir("fuzz");
    let doc = cornell_json();
    std::fs::write(d.join("b.bin"), cornell_bin(&doc)).unwrap();
    std::fs::write(d.join("t.png"), small_png()).unwrap();
    std::fs::write(d.join("big.png"), png_header_only(4096, 4096)).unwrap();
    std::fs::create_dir_all(d.join("dir")).unwrap();
    #[cfg(unix)]
    {
        let _ = std::process::Command::new("mkfifo")
            .arg(d.join("pipe"))
            .status();
        let _ = std::os::unix::fs::symlink("/etc/passwd", d.join("link"));
    }
    d
}

fn small_png() -> Vec<u8> {
    let mut out = Vec::new();
    let px: Vec<u8> = (0..4 * 4 * 3).map(|i| (i * 17) as u8).collect();
    image::write_buffer_with_format(
        &mut std::io::Cursor::new(&mut out),
        &px,
        4,
        4,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .unwrap();
    out
}

/// The seed corpus, as JSON documents with their binary chunk (None: .gltf).
fn corpus() -> Vec<(Value, Option<Vec<u8>>)> {
    let mut out = Vec::new();
    let cornell = cornell_json();
    out.push((cornell.clone(), None));
    // The Cornell box as a GLB.
    let bin = cornell_bin(&cornell);
    let mut glb_doc = cornell.clone();
    glb_doc["buffers"][0] = json!({"byteLength": bin.len()});
    out.push((glb_doc, Some(bin)));
    // The Cornell box reading its buffer from a file.
    let mut file_doc = cornell.clone();
    file_doc["buffers"][0]["uri"] = json!("b.bin");
    out.push((file_doc, None));
    // A triangle GLB, plain and with a sparse POSITION (no base view), with
    // a texture in a buffer view and a TEXCOORD_0.
    let (mut tri, mut bin) = triangle_doc();
    tri["buffers"][0] = json!({"byteLength": bin.len()});
    out.push((tri.clone(), Some(bin.clone())));
    let view = |tri: &mut Value, bin: &mut Vec<u8>, bytes: &[u8]| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let views = tri["bufferViews"].as_array_mut().unwrap();
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend(bytes);
        views.len() - 1
    };
    let idx = view(&mut tri, &mut bin, &[1u8, 2]);
    let val = view(&mut tri, &mut bin, &f32_bytes(&[1., 0., 0., 0., 0., -1.]));
    let uv = view(&mut tri, &mut bin, &f32_bytes(&[0., 0., 1., 0., 0., 1.]));
    let png = view(&mut tri, &mut bin, &small_png());
    let accessors = tri["accessors"].as_array_mut().unwrap();
    accessors[0] = json!({"componentType": 5126, "count": 3, "type": "VEC3",
        "min": [0, 0, -1], "max": [1, 0, 0],
        "sparse": {"count": 2, "indices": {"bufferView": idx, "componentType": 5121},
                   "values": {"bufferView": val}}});
    accessors.push(json!({"bufferView": uv, "componentType": 5126, "count": 3, "type": "VEC2"}));
    tri["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(2);
    tri["meshes"][0]["primitives"][0]["material"] = json!(0);
    tri["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    tri["textures"] = json!([{"source": 0, "sampler": 0}]);
    tri["samplers"] = json!([{}]);
    tri["images"] = json!([{"bufferView": png, "mimeType": "image/png"}]);
    tri["buffers"][0] = json!({"byteLength": bin.len()});
    out.push((tri.clone(), Some(bin.clone())));
    // The same with the image from a file and the buffer embedded.
    let mut tri_file = tri;
    tri_file["images"] = json!([{"uri": "t.png"}]);
    tri_file["buffers"][0]["uri"] = json!(data_uri(&bin));
    out.push((tri_file, None));
    // A small node DAG.
    out.push((node_dag(6), None));
    out
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

/// Paths to every value in `doc` (object keys and array indices).
fn paths(doc: &Value) -> Vec<Vec<Value>> {
    let mut out = Vec::new();
    let mut stack = vec![(doc, Vec::new())];
    while let Some((v, path)) = stack.pop() {
        match v {
            Value::Object(m) => {
                for (k, c) in m {
                    let mut p = path.clone();
                    p.push(json!(k));
                    stack.push((c, p));
                }
            }
            Value::Array(a) => {
                for (i, c) in a.iter().enumerate() {
                    let mut p = path.clone();
                    p.push(json!(i));
                    stack.push((c, p));
                }
            }
            _ => {}
        }
        out.push(path);
    }
    out
}

fn get_mut<'a>(doc: &'a mut Value, path: &[Value]) -> &'a mut Value {
    let mut v = doc;
    for seg in path {
        v = match seg {
            Value::String(k) => &mut v[k.as_str()],
            Value::Number(i) => &mut v[i.as_u64().unwrap() as usize],
            _ => unreachable!(),
        };
    }
    v
}

const NUMBERS: &[f64] = &[
    0.0,
    1.0,
    2.0,
    3.0,
    4.0,
    -1.0,
    0.5,
    255.0,
    256.0,
    65535.0,
    65536.0,
    2147483647.0,
    4294967295.0,
    4294967296.0,
    9007199254740992.0,
    1e19,
    1e39,
    -1e39,
    1e-45,
    1e-40,
    3.5,
    1.5707964,
    5120.0,
    5121.0,
    5122.0,
    5123.0,
    5125.0,
    5126.0,
    34962.0,
];

const URIS: &[&str] = &[
    "b.bin",
    "t.png",
    "big.png",
    "dir",
    "pipe",
    "link",
    "/etc/passwd",
    "/dev/zero",
    "../../../../etc/passwd",
    "%2e%2e/%2e%2e/etc/passwd",
    "file:///etc/passwd",
    "http://localhost/x",
    "data:application/octet-stream;base64,AAAA",
    "data:,x",
    "data:;base64,!!!",
    "",
    ".",
    "fuzz.gltf",
    "%00",
    "%ff%fe",
    "b.bin%",
    "C:\\x",
];

const KEYS: &[&str] = &[
    "count",
    "byteOffset",
    "byteLength",
    "byteStride",
    "bufferView",
    "componentType",
    "buffer",
    "mesh",
    "children",
    "sparse",
    "indices",
    "camera",
    "source",
    "scale",
    "matrix",
    "uri",
    "type",
    "mode",
    "normalized",
];

/// A random JSON value of a kind loaders trip on.
fn random_value(rng: &mut Rng, depth: usize) -> Value {
    match rng.below(if depth > 1 { 5 } else { 8 }) {
        0 | 1 => json!(*rng.pick(NUMBERS)),
        2 => json!(rng.below(12)),
        3 => json!(*rng.pick(URIS)),
        4 => rng
            .pick(&[
                json!(null),
                json!(true),
                json!(false),
                json!("VEC3"),
                json!("SCALAR"),
            ])
            .clone(),
        5 => Value::Array(
            (0..rng.below(5))
                .map(|_| random_value(rng, depth + 1))
                .collect(),
        ),
        6 => {
            let mut m = serde_json::Map::new();
            for _ in 0..rng.below(4) {
                m.insert(rng.pick(KEYS).to_string(), random_value(rng, depth + 1));
            }
            Value::Object(m)
        }
        _ => {
            json!({"count": rng.below(5), "indices": {"bufferView": rng.below(4), "componentType": 5121},
                    "values": {"bufferView": rng.below(4)}})
        }
    }
}

/// One structural change somewhere in `doc`.
fn mutate_json(doc: &mut Value, rng: &mut Rng) {
    let all = paths(doc);
    let path = rng.pick(&all).clone();
    let target = get_mut(doc, &path);
    match rng.below(10) {
        // Replace the value, often by one of the same shape.
        0..=3 => {
            *target = match target {
                Value::Number(_) if rng.chance(0.5) => json!(rng.below(8)),
                Value::Number(_) => json!(*rng.pick(NUMBERS)),
                Value::String(s) if s.starts_with("data:") && rng.chance(0.7) => {
                    // Keep most of a buffer, with bytes changed inside it.
                    let mut b = base64_decode(s).unwrap_or_default();
                    for _ in 0..1 + rng.below(8) {
                        if !b.is_empty() {
                            let i = rng.below(b.len());
                            b[i] = rng.next() as u8;
                        }
                    }
                    if rng.chance(0.2) {
                        let keep = rng.below(b.len() + 1);
                        b.truncate(keep);
                    }
                    json!(data_uri(&b))
                }
                Value::String(_) => json!(*rng.pick(URIS)),
                // Arrays and objects mostly keep their shape (else it is
                // only a parse error): numbers inside them are reached by
                // other picks.
                Value::Array(a) if rng.chance(0.7) => {
                    let n = a.len();
                    json!((0..n)
                        .map(|_| json!(*rng.pick(NUMBERS)))
                        .collect::<Vec<_>>())
                }
                _ => random_value(rng, 0),
            }
        }
        // Add or remove a key.
        4 | 5 => {
            if let Value::Object(m) = target {
                if rng.chance(0.5) && !m.is_empty() {
                    let k = m.keys().nth(rng.below(m.len())).unwrap().clone();
                    m.remove(&k);
                } else {
                    m.insert(rng.pick(KEYS).to_string(), random_value(rng, 0));
                }
            } else {
                *target = random_value(rng, 0);
            }
        }
        // Duplicate, drop or reorder array elements (node lists become DAGs).
        6 | 7 => {
            if let Value::Array(a) = target {
                if !a.is_empty() {
                    let i = rng.below(a.len());
                    match rng.below(3) {
                        0 => {
                            let v = a[i].clone();
                            a.push(v);
                        }
                        1 => {
                            a.remove(i);
                        }
                        _ => {
                            let j = rng.below(a.len());
                            a.swap(i, j);
                        }
                    }
                }
            } else {
                *target = json!([rng.below(8), rng.below(8)]);
            }
        }
        // Point a child list at random nodes (cycles, deep chains).
        8 => {
            let n = doc["nodes"].as_array().map_or(0, Vec::len);
            let i = rng.below(n);
            let children: Vec<usize> = (0..1 + rng.below(3)).map(|_| rng.below(n)).collect();
            if let Some(node) = doc
                .get_mut("nodes")
                .and_then(|v| v.get_mut(i))
                .and_then(Value::as_object_mut)
            {
                node.insert("children".into(), json!(children));
            }
        }
        // Make an accessor sparse, sometimes without a base view.
        _ => {
            let n = doc["accessors"].as_array().map_or(0, Vec::len);
            let views = doc["bufferViews"].as_array().map_or(1, Vec::len);
            let i = rng.below(n);
            let sparse = json!({"count": 1 + rng.below(4),
                "indices": {"bufferView": rng.below(views), "componentType": *rng.pick(&[5121, 5123, 5125]),
                            "byteOffset": rng.below(3) * 4},
                "values": {"bufferView": rng.below(views)}});
            let drop_view = rng.chance(0.5);
            if let Some(acc) = doc
                .get_mut("accessors")
                .and_then(|v| v.get_mut(i))
                .and_then(Value::as_object_mut)
            {
                acc.insert("sparse".into(), sparse);
                if drop_view {
                    acc.remove("bufferView");
                }
            }
        }
    }
}

fn base64_decode(s: &str) -> Option<Vec<u8>> {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD
        .decode(s.split_once(',')?.1)
        .ok()
}

/// Byte-level damage: flips, interesting words (lengths in GLB headers),
/// truncation, insertion, duplication.
fn mutate_bytes(b: &mut Vec<u8>, rng: &mut Rng) {
    if b.is_empty() {
        b.push(b'{');
        return;
    }
    let i = rng.below(b.len());
    match rng.below(6) {
        0 => b[i] ^= 1 << rng.below(8),
        1 => b[i] = rng.next() as u8,
        2 => {
            let words = [
                0u32,
                1,
                2,
                12,
                20,
                0x7FFF_FFFF,
                0xFFFF_FFFF,
                0x4E4F_534A,
                0x004E_4942,
            ];
            let w = rng.pick(&words).to_le_bytes();
            let at = (i / 4 * 4).min(b.len().saturating_sub(4));
            for (k, x) in w.iter().enumerate() {
                if let Some(slot) = b.get_mut(at + k) {
                    *slot = *x;
                }
            }
        }
        3 => b.truncate(i),
        4 => {
            let n = 1 + rng.below(8);
            let junk: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
            b.splice(i..i, junk);
        }
        _ => {
            let end = (i + 1 + rng.below(64)).min(b.len());
            let chunk = b[i..end].to_vec();
            let at = rng.below(b.len());
            b.splice(at..at, chunk);
        }
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
    let baseline = LIVE.load(Relaxed);
    PEAK.store(baseline, Relaxed);
    let started = Instant::now();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        load_bytes(&path, &case.bytes, &options).map(|s| {
            // What the renderer does first with a scene.
            let bounds = s.bounds();
            let state = s.rest_state();
            (s, bounds, state)
        })
    }));
    let took = started.elapsed();
    let peak = PEAK.load(Relaxed).saturating_sub(baseline);
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
