//! libFuzzer over `isr::scene::obj_load::load_bytes` and what the renderer
//! first does with a scene. The input is the OBJ file; its MTL libraries and
//! textures resolve in a temporary folder under the default (safe) policy
//! (write MTL files and PNGs there to reach the library reader). Budgets
//! are tightened as in tests/fuzz_loader.rs.
#![no_main]

use isr::scene::limits::Limits;
use isr::scene::obj_load::load_bytes;
use isr::scene::LoadOptions;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join("isr-fuzz-obj-target");
    let _ = std::fs::create_dir_all(&dir);
    let options = LoadOptions {
        allow_outside_uris: false,
        limits: Limits {
            scene_file_bytes: 8 << 20,
            line_bytes: 1 << 20,
            material_library_bytes: 1 << 20,
            description_bytes: 1 << 16,
            buffer_bytes: 8 << 20,
            image_file_bytes: 1 << 20,
            texture_dimension: 1024,
            texture_pixels: 1 << 18,
            node_visits: 1 << 12,
            hierarchy_depth: 64,
            triangles: 1 << 15,
            vertices: 1 << 15,
            coordinate: 1e6,
            min_extent: 1e-6,
        },
    };
    if let Ok(scene) = load_bytes(&dir.join("f.obj"), data, &options) {
        let _ = scene.bounds();
        let _ = scene.rest_state();
        let _ = scene.triangle_count();
    }
});
