//! The Sibenik nave of `tests/shadow_leaks.rs` and
//! `examples/direct_against_truth.rs` (which includes this file with
//! `#[path]`): the cathedral (73,564 triangles, 40 m long) seen down the
//! nave, lit from its middle at half its height by a spot aimed at the
//! floor or by a point light.

use glam::Vec3;
use isr::scene::{Camera, Light, LightKind, Scene};

/// The cathedral from the archive with the nave's camera and no light yet.
pub fn nave() -> anyhow::Result<Scene> {
    let path = isr::scene::description::archive_root().join("sibenik/sibenik.obj");
    let mut scene = isr::scene::load_file(&path, &Default::default())
        .map_err(|e| anyhow::anyhow!("{e:#}: {}", isr::scene::description::archive_hint()))?;
    scene.camera = Camera::look_at(
        Vec3::new(-17.0, -8.0, 0.0),
        Vec3::new(8.0, -4.0, 0.0),
        Vec3::Y,
        60f32.to_radians(),
        0.05,
    );
    Ok(scene)
}

/// The nave's lights by name: a spot hung at the origin aimed at the
/// floor (1500 cd, cones 45 and 60 degrees), a point light there (300 cd).
pub fn lights() -> [(&'static str, Light); 2] {
    let hung = Vec3::ZERO;
    let base = Light {
        kind: LightKind::Spot,
        position: hung,
        direction: -Vec3::Y,
        color: Vec3::ONE,
        intensity: 1500.0,
        inner_cone: 45f32.to_radians(),
        outer_cone: 60f32.to_radians(),
        range: None,
    };
    [
        ("a spot hung in the nave", base),
        (
            "a point light hung in the nave",
            Light {
                kind: LightKind::Point,
                intensity: 300.0,
                inner_cone: 0.0,
                outer_cone: std::f32::consts::FRAC_PI_2,
                ..base
            },
        ),
    ]
}
