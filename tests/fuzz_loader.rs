//! Property test of the glTF loader on stable Rust (issues 14 and 27):
//! thousands of files generated and mutated from a seed corpus (the Cornell
//! box as glTF and as GLB, small GLBs with sparse accessors, textures and
//! node DAGs), with a fixed seed. Every input must give a scene whose data
//! is sane or an error, never a panic, a slow load (a hang) or a large
//! allocation, under `Limits::FUZZ`; the loader is called without its panic
//! guard (`load_bytes`). The OBJ and description loaders have their own,
//! tests/fuzz_loader_obj.rs.
//!
//! Inputs that fail are written to `tests/fuzz-regressions/` (commit them);
//! every file there is replayed first. `ISR_FUZZ_CASES=N` runs N mutated
//! cases instead of the default; `ISR_FUZZ_SEED=S` changes the seed;
//! `ISR_FUZZ_TRACE=1` writes each input to `target/fuzz-last.*` before it is
//! loaded (to find the input that aborted the process, should one).
mod common;
#[path = "fuzz_loader/harness.rs"]
mod harness;
#[path = "fuzz_loader/mutate.rs"]
mod mutate;

use common::gltf::*;
use common::measure::Counting;
use common::temp_dir;
use isr::scene::gltf_load::{load_bytes, LoadOptions};
use isr::scene::limits::Limits;
use mutate::{mutate_bytes, mutate_json, Rng};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Counts each thread's live bytes and their peak, to catch allocations no
/// budget bounds.
#[global_allocator]
static ALLOC: Counting = Counting;

/// Tight budgets so that what they allow is small and anything else stands out.
const FUZZ_LIMITS: Limits = Limits::FUZZ;
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

/// Loads one glTF input and checks what it gives: `Ok(None)` for a sane
/// scene, `Ok(Some(error))`, `Err(problem)` (`harness::run`).
fn check(dir: &Path, case: &Case) -> Result<Option<String>, String> {
    let options = LoadOptions {
        allow_outside_uris: false,
        limits: FUZZ_LIMITS,
    };
    match load_bytes(&dir.join(case.name), &case.bytes, &options) {
        Err(e) => {
            let msg = format!("{e:#}");
            if msg.is_empty() || msg.contains("root:x:") {
                return Err(format!("unclear or leaking error: {msg}"));
            }
            Ok(Some(msg))
        }
        Ok(s) => {
            // What the renderer does first with a scene.
            let bounds = s.bounds();
            let state = s.rest_state();
            sane(&s, bounds, &state).map_or(Ok(None), Err)
        }
    }
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

#[test]
fn loader_never_panics_hangs_or_allocates_without_bound() {
    let epoch = harness::start();
    let dir = fixture_dir();
    let trace = std::env::var_os("ISR_FUZZ_TRACE").is_some();
    let trace_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target");
    let mut failures = Vec::new();
    // Some(the loader's error or None for a scene), None: the input failed.
    let run = |case: Case, keep: bool, failures: &mut Vec<String>| -> Option<Option<String>> {
        let ext = Path::new(case.name).extension().unwrap().to_str().unwrap();
        if trace {
            let _ = std::fs::write(trace_dir.join(format!("fuzz-last.{ext}")), &case.bytes);
        }
        harness::run(ext, &case.bytes, keep, failures, || check(&dir, &case))
    };

    // Every input that ever failed, first.
    let mut replayed = 0;
    for (ext, bytes, p) in harness::regressions(&["gltf", "glb"]) {
        let name = if ext == "glb" {
            "fuzz.glb"
        } else {
            "fuzz.gltf"
        };
        if run(Case { name, bytes }, false, &mut failures).is_none() {
            let last = failures.pop().unwrap();
            failures.push(format!("regression {}: {last}", p.display()));
        }
        replayed += 1;
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
            Some(Some(e)) => *messages.entry(harness::message_key(&e)).or_insert(0usize) += 1,
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
