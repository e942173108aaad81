//! The court of `tests/shadow_leaks.rs` and `examples/direct_against_truth.rs`
//! (which includes this file with `#[path]`): a floor, two thin walls
//! meeting at a corner and a turned block, grey 0.6, seen from above one
//! corner.

use glam::Vec3;
use isr::scene::{cuboid, Camera, Light, LightKind, Scene};

/// The court lit by `light`.
pub fn court(light: Light) -> Scene {
    let camera = Camera::look_at(
        Vec3::new(2.6, 2.2, 2.8),
        Vec3::new(-0.6, 0.2, -0.6),
        Vec3::Y,
        50f32.to_radians(),
        0.05,
    );
    let mut s = Scene::empty("court", light, camera);
    let grey = s.add_material("grey", Vec3::splat(0.6));
    // Thin walls, seen and lit from both sides.
    s.materials[grey].double_sided = true;
    let (f, h, w) = (2.0, 0.8, 2.0);
    s.add_quad(
        "floor",
        [
            Vec3::new(-f, 0.0, f),
            Vec3::new(f, 0.0, f),
            Vec3::new(f, 0.0, -f),
            Vec3::new(-f, 0.0, -f),
        ],
        grey,
    );
    s.add_quad(
        "wall-x",
        [
            Vec3::new(-w, 0.0, w),
            Vec3::new(-w, 0.0, -w),
            Vec3::new(-w, h, -w),
            Vec3::new(-w, h, w),
        ],
        grey,
    );
    s.add_quad(
        "wall-z",
        [
            Vec3::new(-w, 0.0, -w),
            Vec3::new(w, 0.0, -w),
            Vec3::new(w, h, -w),
            Vec3::new(-w, h, -w),
        ],
        grey,
    );
    let (v, i) = cuboid(Vec3::new(0.3, 0.35, -0.2), Vec3::splat(0.7), 0.4);
    s.add_mesh("block", v, i, grey);
    s
}

/// The court's low suns by name: white, irradiance 3 W/m^2.
pub fn low_suns() -> [(&'static str, Light); 3] {
    let sun = |d: Vec3| Light {
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: d.normalize(),
        color: Vec3::ONE,
        intensity: 3.0,
        inner_cone: 0.0,
        outer_cone: std::f32::consts::FRAC_PI_2,
        range: None,
    };
    [
        ("a low sun behind the walls", sun(Vec3::new(1.0, -0.5, 0.6))),
        ("a low sun in front", sun(Vec3::new(-1.0, -0.45, 0.35))),
        ("a sun grazing a wall", sun(Vec3::new(0.6, -0.3, -1.0))),
    ]
}
