//! The house rules a reader of the code relies on, held as tests (no GPU,
//! milliseconds): no Rust file in `src/` or `tests/` over 600 lines, so
//! that a file stays one concern a reader can hold (split by concern, not
//! at line 600); and no ignored test in `tests/`, so that every test runs
//! with the suite (a measurement that only prints a table is an example or
//! a bench, not a test).

use std::path::{Path, PathBuf};

/// The most lines a `.rs` file in `src/` or `tests/` may have.
const MAX_LINES: usize = 600;

/// Every `.rs` file under `dir`, in a stable order.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = vec![];
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
    out
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn no_rust_file_in_src_or_tests_is_over_600_lines() {
    let mut long = vec![];
    for dir in ["src", "tests"] {
        for f in rust_files(&root().join(dir)) {
            let lines = std::fs::read_to_string(&f).unwrap().lines().count();
            if lines > MAX_LINES {
                let name = f.strip_prefix(root()).unwrap().display().to_string();
                long.push(format!("{name}: {lines} lines"));
            }
        }
    }
    assert!(
        long.is_empty(),
        "over {MAX_LINES} lines (split by concern):\n{}",
        long.join("\n")
    );
}

#[test]
fn no_test_is_ignored() {
    // Spelled in two pieces so that this file does not find itself.
    let attribute = concat!("#[", "ignore");
    let mut ignored = vec![];
    for f in rust_files(&root().join("tests")) {
        let text = std::fs::read_to_string(&f).unwrap();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim_start();
            let conditional = line.starts_with("#[cfg_attr") && line.contains("ignore");
            if line.starts_with(attribute) || conditional {
                let name = f.strip_prefix(root()).unwrap().display().to_string();
                ignored.push(format!("{name}:{}: {line}", i + 1));
            }
        }
    }
    assert!(
        ignored.is_empty(),
        "ignored tests (make a measurement an example or a bench):\n{}",
        ignored.join("\n")
    );
}

/// The words of an identifier: `HisrCutHeader` and `hisr_cut_header` are
/// both `hisr cut header`.
fn words(identifier: &str) -> Vec<String> {
    let mut out = vec![];
    for part in identifier.split('_').filter(|p| !p.is_empty()) {
        let mut word = String::new();
        let chars: Vec<char> = part.chars().collect();
        for (i, &c) in chars.iter().enumerate() {
            // A capital starts a word, unless the previous is one too and the
            // next is not lower case (HISR stays one word, HisrCut is two).
            let boundary = c.is_uppercase()
                && i > 0
                && (chars[i - 1].is_lowercase()
                    || chars.get(i + 1).is_some_and(|n| n.is_lowercase()));
            if boundary && !word.is_empty() {
                out.push(std::mem::take(&mut word));
            }
            word.push(c.to_ascii_lowercase());
        }
        out.push(word);
    }
    out
}

/// A source file's code in pieces: the text outside comments and string
/// literals, and each string literal, by line; for Rust, up to its unit
/// tests (which may exercise shared code with any method).
struct Code {
    /// (line, code outside comments and literals).
    text: Vec<(usize, String)>,
    /// (line where it starts, contents).
    literals: Vec<(usize, String)>,
}

fn code_of(path: &Path) -> Code {
    let source = std::fs::read_to_string(path).unwrap();
    let source = match source.find("#[cfg(test)]") {
        Some(k) => &source[..k],
        None => &source[..],
    };
    let chars: Vec<char> = source.chars().collect();
    let (mut text, mut literals) = (vec![], vec![]);
    let (mut line, mut current, mut i) = (1, String::new(), 0);
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
            continue;
        }
        if c == '/' && next == Some('*') {
            i += 2;
            while i + 1 < chars.len() && !(chars[i] == '*' && chars[i + 1] == '/') {
                line += (chars[i] == '\n') as usize;
                i += 1;
            }
            i += 2;
            continue;
        }
        // A char literal ('"', '\''), not a lifetime.
        if c == '\'' && next.is_some() {
            let end = if next == Some('\\') { i + 3 } else { i + 2 };
            if chars.get(end) == Some(&'\'') {
                i = end + 1;
                continue;
            }
        }
        if c == '"' {
            let start = line;
            let mut literal = String::new();
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                if chars[i] == '\\' {
                    i += 1;
                }
                if chars[i] == '\n' {
                    line += 1;
                }
                literal.push(chars[i]);
                i += 1;
            }
            literals.push((start, literal));
            current.push(' ');
            i += 1;
            continue;
        }
        if c == '\n' {
            text.push((line, std::mem::take(&mut current)));
            line += 1;
        } else {
            current.push(c);
        }
        i += 1;
    }
    text.push((line, current));
    Code { text, literals }
}

/// What names a method of `keys`: a string literal that is a method's key
/// (`literal`), or in code a path into its module (`methods::hisr`) or an
/// identifier whose words hold its key's (`HisrCutHeader`,
/// `isr_base_level`). The keys that are everyday words count less: "none"
/// (also a `--visibility`) only as a path, "reference" as a path or a
/// literal.
fn names_a_method(code: &str, literal: Option<&str>, keys: &[&str]) -> Option<String> {
    for key in keys {
        let module = key.replace('-', "_");
        if literal == Some(*key) && *key != "none" {
            return Some(format!("the literal \"{key}\""));
        }
        if code.contains(&format!("methods::{module}")) {
            return Some(format!("the path methods::{module}"));
        }
        if matches!(*key, "none" | "reference") {
            continue;
        }
        let key_words: Vec<&str> = key.split('-').collect();
        for identifier in code.split(|c: char| !(c.is_alphanumeric() || c == '_')) {
            let w = words(identifier);
            if w.windows(key_words.len())
                .any(|s| s.iter().eq(key_words.iter()))
            {
                return Some(format!("the identifier {identifier}"));
            }
        }
    }
    None
}

/// Every file under `dir` (recursively) whose name ends in one of `ends`.
fn files_ending(dir: &Path, ends: &[&str]) -> Vec<PathBuf> {
    let mut out = vec![];
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            out.extend(files_ending(&p, ends));
        } else if ends.iter().any(|e| p.to_string_lossy().ends_with(e)) {
            out.push(p);
        }
    }
    out
}

/// A method is one module (`src/methods/<method>`), one shader folder
/// (`shaders/<method>/`) and one line in the registry: no other module or
/// shader names one, so that adding, changing or removing a method touches
/// only its own files. The code that may name one is listed here, each with
/// why.
#[test]
fn no_shared_module_or_shader_names_a_method() {
    let keys = isr::methods::names();
    let modules: Vec<String> = keys.iter().map(|k| k.replace('-', "_")).collect();
    // (file, the code on the line): where naming a method is the point.
    let allowed: &[(&str, &str)] = &[
        // The program's own name, which the method `isr` shares, and the
        // crate's.
        ("src/cli/mod.rs", "name ="),
        ("src/vk/context/mod.rs", "application_name(c"),
        ("src/main.rs", "isr::cli::run()"),
        // The default method: a key the settings' const holds, below the
        // registry that defines it.
        ("src/settings/mod.rs", "method: Method::new("),
        // FLIP's own words: its reference image and its test image.
        ("src/bench/flip.rs", "for (what, img) in"),
    ];
    let mut found = vec![];
    let shared_rust = files_ending(&root().join("src"), &[".rs"])
        .into_iter()
        .filter(|p| !p.starts_with(root().join("src/methods")));
    let shared_glsl = files_ending(
        &root().join("shaders"),
        &[".glsl", ".vert", ".frag", ".comp"],
    )
    .into_iter()
    .filter(|p| {
        let folder = p
            .parent()
            .unwrap()
            .strip_prefix(root().join("shaders"))
            .unwrap();
        !modules.iter().any(|m| folder == Path::new(m))
    });
    for f in shared_rust.chain(shared_glsl) {
        let name = f.strip_prefix(root()).unwrap().display().to_string();
        let code = code_of(&f);
        let text_of = |line: usize| {
            code.text
                .iter()
                .find(|(l, _)| *l == line)
                .map_or("", |(_, t)| t.as_str())
        };
        let mut report = |line: usize, what: String| {
            let text = text_of(line);
            if !allowed
                .iter()
                .any(|(file, code)| *file == name && text.contains(code))
            {
                found.push(format!("{name}:{line}: {what}: {}", text.trim()));
            }
        };
        for (line, text) in &code.text {
            if let Some(what) = names_a_method(text, None, &keys) {
                report(*line, what);
            }
        }
        for (line, literal) in &code.literals {
            if let Some(what) = names_a_method("", Some(literal), &keys) {
                report(*line, what);
            }
        }
    }
    assert!(
        found.is_empty(),
        "shared code that names a method (move it into the method's module or \
         shader folder, or make it a property of the registry's descriptor):\n{}",
        found.join("\n")
    );
}

#[test]
fn words_split_snake_and_camel_case() {
    assert_eq!(words("HisrCutHeader"), ["hisr", "cut", "header"]);
    assert_eq!(words("HISR_TAU"), ["hisr", "tau"]);
    assert_eq!(words("isr_base_level"), ["isr", "base", "level"]);
    assert_eq!(words("LPVSize"), ["lpv", "size"]);
    let keys = ["isr", "multires-gather", "none", "reference"];
    let named = |code: &str, literal: Option<&str>| names_a_method(code, literal, &keys);
    assert!(named("", Some("multires-gather")).is_some());
    assert!(named("", Some("reference")).is_some());
    assert!(named("use crate::methods::isr::BASE;", None).is_some());
    assert!(named("use crate::methods::none::KEY;", None).is_some());
    assert!(named("u.isr_base_level = 0;", None).is_some());
    assert!(named("let a = MultiresGatherPass::new();", None).is_some());
    // A visibility of none, a dense reference, another word.
    assert!(named("", Some("none")).is_none());
    assert!(named("let reference = Visibility::None;", None).is_none());
    assert!(named("let disr = mismatch;", None).is_none());
}
