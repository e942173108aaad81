//! Compiles every GLSL stage in `shaders/` and its folders (`shaders/hisr/`,
//! one per method or module that has shaders of its own) to SPIR-V with
//! glslang and embeds the result in the binary (see `src/vk/shaders.rs`), so
//! `isr` runs from any directory. A shader is named by its path under
//! `shaders/` (`hisr/cut.comp`).
//!
//! Files ending in `.vert`, `.frag` and `.comp` are compiled; `.glsl` files are
//! headers, reached only through `#include "..."` (resolved relative to
//! `shaders/`, so `#include "hisr/hisr.glsl"` reads the same file from any
//! folder). A compile error fails the build and names the file and line.

use glslang::error::GlslangError;
use glslang::include::{IncludeHandler, IncludeResult, IncludeType};
use glslang::{
    Compiler, CompilerOptions, ShaderInput, ShaderMessage, ShaderSource, ShaderStage,
    SourceLanguage, SpirvVersion, Target, VulkanVersion,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

struct ShaderDirIncludes {
    dir: PathBuf,
}

impl IncludeHandler for ShaderDirIncludes {
    fn include(
        &mut self,
        _ty: IncludeType,
        header_name: &str,
        _includer_name: &str,
        _depth: usize,
    ) -> Option<IncludeResult> {
        let path = self.dir.join(header_name);
        let data = std::fs::read_to_string(&path).ok()?;
        Some(IncludeResult {
            name: header_name.to_string(),
            data,
        })
    }
}

fn stage_of(path: &Path) -> Option<ShaderStage> {
    match path.extension()?.to_str()? {
        "vert" => Some(ShaderStage::Vertex),
        "frag" => Some(ShaderStage::Fragment),
        "comp" => Some(ShaderStage::Compute),
        _ => None,
    }
}

/// glslang reports the main source as string `0`; name the file instead so
/// errors read `shaders/foo.frag:12: ...`.
fn readable_log(file: &str, err: &GlslangError) -> String {
    let text = err.to_string();
    text.replace("ERROR: 0:", &format!("ERROR: {file}:"))
        .replace("WARNING: 0:", &format!("WARNING: {file}:"))
}

/// Every file in `dir` and its folders.
fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let entries =
        std::fs::read_dir(dir).unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()));
    for entry in entries {
        let path = entry.unwrap().path();
        if path.is_dir() {
            println!("cargo:rerun-if-changed={}", path.display());
            files_under(&path, out);
        } else {
            out.push(path);
        }
    }
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let shader_dir = manifest.join("shaders");
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    println!("cargo:rerun-if-changed=shaders");

    let mut entries = Vec::new();
    files_under(&shader_dir, &mut entries);
    entries.sort();

    let compiler = Compiler::acquire().expect("glslang failed to initialise");
    let options = CompilerOptions {
        source_language: SourceLanguage::GLSL,
        target: Target::Vulkan {
            version: VulkanVersion::Vulkan1_3,
            spirv_version: SpirvVersion::SPIRV1_6,
        },
        version_profile: None,
        messages: ShaderMessage::DEFAULT | ShaderMessage::VULKAN_RULES | ShaderMessage::SPV_RULES,
    };

    let mut table = String::from(
        "/// Every compiled shader: (file name in `shaders/`, SPIR-V bytes).\n\
         pub static SPIRV: &[(&str, &[u8])] = &[\n",
    );
    let mut failures = Vec::new();
    for path in &entries {
        println!("cargo:rerun-if-changed={}", path.display());
        let Some(stage) = stage_of(path) else {
            continue;
        };
        let name = path
            .strip_prefix(&shader_dir)
            .unwrap()
            .to_str()
            .unwrap()
            .replace('\\', "/");
        let display = format!("shaders/{name}");
        let source = std::fs::read_to_string(path).unwrap();
        let source = ShaderSource::from(source);
        let mut includes = ShaderDirIncludes {
            dir: shader_dir.clone(),
        };
        let result = ShaderInput::new(
            &source,
            stage,
            &options,
            None::<&[(&str, Option<&str>)]>,
            Some(&mut includes),
        )
        .and_then(|input| compiler.create_shader(input))
        .and_then(|shader| shader.compile());
        match result {
            Ok(words) => {
                let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
                let spv = out_dir.join(format!("{}.spv", name.replace('/', "__")));
                std::fs::write(&spv, bytes).unwrap();
                writeln!(
                    table,
                    "    ({name:?}, include_bytes!({:?})),",
                    spv.display()
                )
                .unwrap();
            }
            Err(err) => failures.push(format!("{display}:\n{}", readable_log(&display, &err))),
        }
    }
    table.push_str("];\n");
    if !failures.is_empty() {
        for f in &failures {
            eprintln!("{f}");
        }
        panic!(
            "{} shader(s) failed to compile:\n{}",
            failures.len(),
            failures.join("\n")
        );
    }
    std::fs::write(out_dir.join("shaders.rs"), table).unwrap();
}
