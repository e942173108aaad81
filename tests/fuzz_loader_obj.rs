//! Property test of the OBJ and scene-description loaders on stable Rust,
//! with a fixed seed, in two parts: cases made by the generators of
//! `isr::scene::fuzzing` (the same ones the `cargo fuzz` targets
//! `obj_loader` and `description` drive with libFuzzer's bytes; here a
//! seeded generator gives the bytes), and small OBJ seeds mutated line by
//! line and byte by byte. Every input must give a scene that passes
//! `fuzzing::check_scene` (what the renderer can take, warnings few, short
//! and escaped) or an error that passes `fuzzing::check_message` (one
//! short line, no byte of the file raw); never a panic, a load over 3 s or
//! an allocation peak over 96 MiB, under `Limits::FUZZ`. The loaders are
//! called without their panic guard (`load_bytes`).
//!
//! Time budget: a minute in release on 2 loaded cores (16,000 cases of
//! each kind take about 12 s).
//! Inputs that fail are kept in `tests/fuzz-regressions/` (an OBJ as
//! `.obj`, a generator's bytes as `.objgen` or `.descgen`, which is also
//! what the `cargo fuzz` targets take after their first byte: commit them)
//! and replayed first. `ISR_FUZZ_CASES=N` runs N cases of each kind
//! instead of the default, `ISR_FUZZ_SEED=S` another seed.
mod common;
#[path = "fuzz_loader/harness.rs"]
mod harness;
// The glTF mutations go unused here.
#[allow(dead_code)]
#[path = "fuzz_loader/mutate.rs"]
mod mutate;

use common::measure::Counting;
use common::temp_dir;
use isr::scene::fuzzing::{self, Bytes};
use isr::scene::limits::Limits;
use isr::scene::{description, obj_load, LoadOptions};
use mutate::{mutate_bytes, Rng};
use std::path::Path;

/// Counts each thread's live bytes and their peak, to catch allocations no
/// budget bounds.
#[global_allocator]
static ALLOC: Counting = Counting;

fn options() -> LoadOptions {
    LoadOptions {
        allow_outside_uris: false,
        limits: Limits::FUZZ,
    }
}

/// What a load gave, as `harness::run` takes it.
fn outcome(loaded: anyhow::Result<isr::scene::Scene>) -> Result<Option<String>, String> {
    match loaded {
        Ok(scene) => fuzzing::check_scene(&scene, &Limits::FUZZ).map(|()| None),
        Err(e) => {
            let m = format!("{e:#}");
            fuzzing::check_message(&m)?;
            if m.contains("root:x:") {
                return Err(format!("an error quoting /etc/passwd: {m}"));
            }
            Ok(Some(m))
        }
    }
}

/// A generated case, written beside the fixtures and loaded.
fn generated(dir: &Path, case: &fuzzing::Case) -> Result<Option<String>, String> {
    let path = case
        .write(dir)
        .map_err(|e| format!("writing the case: {e}"))?;
    let loaded = if case.name.ends_with(".obj") {
        obj_load::load_bytes(&path, &case.bytes, &options())
    } else {
        description::load_bytes(&path, &case.bytes, &options())
    };
    outcome(loaded)
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

#[test]
fn obj_and_description_loaders_never_panic_hang_or_allocate_without_bound() {
    let epoch = harness::start();
    let dir = temp_dir("fuzz-obj");
    fuzzing::fixtures(&dir).unwrap();
    // The mutated seeds' own libraries.
    for (name, mtl) in OBJ_LIBRARIES {
        std::fs::write(dir.join(name), mtl).unwrap();
    }
    std::fs::write(
        dir.join("big.png"),
        common::gltf::png_header_only(4096, 4096),
    )
    .unwrap();
    let mut failures = Vec::new();
    let mut messages = std::collections::HashMap::new();
    let mut count = |outcome: Option<Option<String>>, what: &str, scenes: &mut usize| match outcome
    {
        Some(None) => *scenes += 1,
        Some(Some(e)) => {
            *messages
                .entry(format!("{what}: {}", harness::message_key(&e)))
                .or_insert(0usize) += 1
        }
        None => {}
    };
    let gen = |ext: &str, bytes: &[u8]| {
        let mut b = Bytes::new(bytes);
        if ext == "descgen" {
            fuzzing::description_case(&mut b)
        } else {
            fuzzing::obj_case(&mut b)
        }
    };

    // Every input that ever failed, first.
    let mut replayed = 0;
    for (ext, bytes, p) in harness::regressions(&["obj", "objgen", "descgen"]) {
        let ran = if ext == "obj" {
            harness::run(&ext, &bytes, false, &mut failures, || {
                outcome(obj_load::load_bytes(
                    &dir.join("fuzz.obj"),
                    &bytes,
                    &options(),
                ))
            })
        } else {
            let case = gen(&ext, &bytes);
            harness::run(&ext, &bytes, false, &mut failures, || {
                generated(&dir, &case)
            })
        };
        if ran.is_none() {
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
        .unwrap_or(16_000);
    let mut rng = Rng(seed);
    let mut scenes = [0usize; 3];
    // Generated OBJ and description cases: each from 256 random bytes.
    for (k, ext) in ["objgen", "descgen"].into_iter().enumerate() {
        for _ in 0..cases {
            let bytes: Vec<u8> = (0..256).map(|_| rng.next() as u8).collect();
            let case = gen(ext, &bytes);
            let ran = harness::run(ext, &bytes, true, &mut failures, || generated(&dir, &case));
            count(ran, ext, &mut scenes[k]);
            if failures.len() > 20 {
                break;
            }
        }
    }
    // The OBJ seeds load; then mutated.
    let obj_seeds = obj_corpus();
    for seed in &obj_seeds {
        if let Err(e) = obj_load::load_bytes(&dir.join("fuzz.obj"), seed.as_bytes(), &options()) {
            panic!("an OBJ seed does not load: {e:#}\n{seed}");
        }
    }
    for i in 0..cases {
        let mut text = rng.pick(&obj_seeds).clone();
        for _ in 0..1 + rng.below(4) {
            mutate_obj(&mut text, &mut rng);
        }
        let mut bytes = text.into_bytes();
        if i % 4 == 0 {
            mutate_bytes(&mut bytes, &mut rng);
        }
        let ran = harness::run("obj", &bytes, true, &mut failures, || {
            outcome(obj_load::load_bytes(
                &dir.join("fuzz.obj"),
                &bytes,
                &options(),
            ))
        });
        count(ran, "obj", &mut scenes[2]);
        if failures.len() > 20 {
            break;
        }
    }
    let mut common: Vec<_> = messages.into_iter().collect();
    common.sort_by_key(|c| std::cmp::Reverse(c.1));
    for (m, n) in common.iter().take(20) {
        println!("{n:6}  {m}");
    }
    println!(
        "fuzz_loader_obj: {replayed} regressions replayed; {cases} generated OBJ cases ({} scenes), {cases} descriptions ({} scenes), {cases} mutated OBJ files ({} scenes); {:.1} s",
        scenes[0],
        scenes[1],
        scenes[2],
        epoch.elapsed().as_secs_f64()
    );
    assert!(
        failures.is_empty(),
        "{} inputs failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    // Each kind must reach past the parsers often enough to mean something.
    for (what, n) in ["generated OBJ", "description", "mutated OBJ"]
        .iter()
        .zip(scenes)
    {
        assert!(n * 20 > cases, "only {n} of {cases} {what} cases loaded");
    }
}
