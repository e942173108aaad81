//! The crate's modules depend downwards only (docs/architecture.md, "Code
//! map"): every
//! `crate::MODULE` a file of `src/MODULE/` or `src/MODULE.rs` names is a
//! module of a lower layer. Read from the source text: `use crate::a::b`,
//! `use crate::{a, b::c}` and paths written inline (`crate::a::f()`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The layers, lowest first. A module may use the modules of the layers
/// below its own, none of its own layer or above.
const LAYERS: &[&[&str]] = &[
    &["settings", "gpu_types", "progress", "scene"],
    &["view", "vk", "bounces"],
    &["frame"],
    &["passes"],
    &["voxel_grid"],
    &["visibility"],
    &["multires"],
    &["regular_vpls"],
    &["methods", "readback"],
    &["method_args", "debug_view", "output"],
    &["renderer", "pathtrace"],
    &["report", "soak", "exact_visibility", "placement"],
    &["viewer", "bench"],
    &["cli"],
];

/// The top-level modules `text` names through `crate::`.
fn crate_paths(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in text.match_indices("crate::") {
        // Skip doc and line comments: only code counts.
        let line_start = text[..i].rfind('\n').map_or(0, |n| n + 1);
        if text[line_start..i].contains("//") {
            continue;
        }
        let rest = &text[i + "crate::".len()..];
        if let Some(list) = rest.strip_prefix('{') {
            // `crate::{a, b::c, d::{e, f}}`: the top-level names at depth 0.
            let mut depth = 0;
            let mut name = String::new();
            let mut at_start = true;
            for c in list.chars() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => at_start = true,
                    c if depth == 0 && at_start && (c.is_alphanumeric() || c == '_') => {
                        name.push(c)
                    }
                    _ => {
                        if !name.is_empty() {
                            out.insert(std::mem::take(&mut name));
                        }
                        if !c.is_whitespace() {
                            at_start = false;
                        }
                    }
                }
            }
            if !name.is_empty() {
                out.insert(name);
            }
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            out.insert(name);
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn modules_depend_only_on_lower_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let layer: BTreeMap<&str, usize> = LAYERS
        .iter()
        .enumerate()
        .flat_map(|(i, ms)| ms.iter().map(move |m| (*m, i)))
        .collect();
    let mut files = vec![];
    rust_files(&src, &mut files);
    let mut seen_modules = BTreeSet::new();
    let mut wrong = vec![];
    for file in &files {
        let relative = file.strip_prefix(&src).unwrap();
        let first = relative.components().next().unwrap().as_os_str();
        let module = first.to_string_lossy().trim_end_matches(".rs").to_string();
        if module == "lib" || module == "main" {
            continue;
        }
        let Some(&own) = layer.get(module.as_str()) else {
            panic!(
                "module {module} ({}) is in no layer of LAYERS",
                relative.display()
            );
        };
        seen_modules.insert(module.clone());
        let text = std::fs::read_to_string(file).unwrap();
        for used in crate_paths(&text) {
            if used == module {
                continue;
            }
            match layer.get(used.as_str()) {
                Some(&l) if l < own => {}
                Some(&l) => wrong.push(format!(
                    "{} (layer {own}) uses crate::{used} (layer {l})",
                    relative.display()
                )),
                None => wrong.push(format!(
                    "{} uses crate::{used}, which is in no layer",
                    relative.display()
                )),
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "imports running up or sideways:\n{}",
        wrong.join("\n")
    );
    // Every layer's module exists (the table is not stale).
    for m in layer.keys() {
        assert!(
            seen_modules.contains(*m),
            "LAYERS names {m}, which src/ lacks"
        );
    }
}

#[test]
fn the_path_reader_finds_every_form() {
    let text = "use crate::a::b;\nuse crate::{c, d::{e, f}, g::h};\nlet x = crate::i::j();\n// crate::k in a comment\n";
    let found: Vec<String> = crate_paths(text).into_iter().collect();
    assert_eq!(found, ["a", "c", "d", "g", "i"]);
}
