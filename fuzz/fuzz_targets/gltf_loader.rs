//! libFuzzer over `isr::scene::gltf_load::load_bytes` and what the renderer
//! first does with a scene. The first byte picks the file name (`.gltf` or
//! `.glb`); the rest is the file. URIs resolve in a temporary folder, under
//! the default (safe) policy. Budgets are `Limits::FUZZ` (shared with the
//! stable fuzz tests), so that libFuzzer's memory limit flags only
//! allocations no budget accounts for.
#![no_main]

use isr::scene::gltf_load::{load_bytes, LoadOptions};
use isr::scene::limits::Limits;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, file)) = data.split_first() else {
        return;
    };
    let dir = std::env::temp_dir().join("isr-fuzz-target");
    let _ = std::fs::create_dir_all(&dir);
    let name = if pick & 1 == 1 { "f.glb" } else { "f.gltf" };
    let options = LoadOptions {
        allow_outside_uris: false,
        limits: Limits::FUZZ,
    };
    if let Ok(scene) = load_bytes(&dir.join(name), file, &options) {
        let _ = scene.bounds();
        let _ = scene.rest_state();
        let _ = scene.triangle_count();
    }
});
