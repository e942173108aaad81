//! Writes the bench's stress scenes (`isr::bench::scenes`) to
//! `assets/NAME.gltf`: `cargo run --release --example stress_scenes`.
//! `tests/bench_scenes.rs` checks that the files match the code.

fn main() -> anyhow::Result<()> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    for s in isr::bench::scenes::SCENES {
        if s.name == "cornell" {
            continue; // assets/cornell.gltf is written by `isr export-builtin`
        }
        let scene = isr::bench::scenes::build(s.name)?;
        let path = dir.join(format!("{}.gltf", s.name));
        isr::output::write_text(&path, &isr::scene::export::to_gltf_json(&scene)?)?;
        println!(
            "wrote {} ({} triangles)",
            path.display(),
            scene.triangle_count()
        );
    }
    Ok(())
}
