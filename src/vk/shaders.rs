//! The SPIR-V of every shader, compiled by `build.rs` and embedded in the
//! binary. Its own module so that `descriptors` (which reflects it) and
//! `pipeline` (which makes shader modules of it) both read it without
//! depending on each other.

use anyhow::{anyhow, Result};

mod embedded {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

/// The SPIR-V words of `shaders/<name>`, compiled by `build.rs`.
pub fn spirv(name: &str) -> Result<Vec<u32>> {
    let bytes = embedded::SPIRV
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, b)| *b)
        .ok_or_else(|| anyhow!("no compiled shader named {name} (is shaders/{name} present?)"))?;
    Ok(ash::util::read_spv(&mut std::io::Cursor::new(bytes))?)
}

/// Names of every embedded shader.
pub fn shader_names() -> impl Iterator<Item = &'static str> {
    embedded::SPIRV.iter().map(|(n, _)| *n)
}
