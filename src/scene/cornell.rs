//! The built-in Cornell box: a 2 m cube open at the front (+z), red left wall,
//! green right wall, two white blocks, and a spot light under the ceiling aimed
//! down and slightly back. `assets/cornell.gltf` is this scene written by
//! `isr export-builtin` (a test checks that the two agree).

use super::{cuboid, Camera, Scene, SpotLight};
use glam::Vec3;

pub fn cornell_box() -> Scene {
    let light = SpotLight {
        position: Vec3::new(0.0, 1.9, 0.0),
        direction: Vec3::new(0.0, -1.0, -0.15).normalize(),
        color: Vec3::ONE,
        intensity: 8.0,
        inner_cone: 45f32.to_radians(),
        outer_cone: 60f32.to_radians(),
        range: None,
    };
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.0, 3.4),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::Y,
        38f32.to_radians(),
        0.05,
    );
    let mut s = Scene::empty("cornell-box", light, camera);
    let white = s.add_material("white", Vec3::splat(0.75));
    let red = s.add_material("red", Vec3::new(0.63, 0.065, 0.05));
    let green = s.add_material("green", Vec3::new(0.14, 0.45, 0.091));
    let v = Vec3::new;
    // Walls face into the box (counter-clockwise seen from inside).
    s.add_quad(
        "floor",
        [
            v(-1., 0., 1.),
            v(1., 0., 1.),
            v(1., 0., -1.),
            v(-1., 0., -1.),
        ],
        white,
    );
    s.add_quad(
        "ceiling",
        [
            v(-1., 2., -1.),
            v(1., 2., -1.),
            v(1., 2., 1.),
            v(-1., 2., 1.),
        ],
        white,
    );
    s.add_quad(
        "back",
        [
            v(-1., 0., -1.),
            v(1., 0., -1.),
            v(1., 2., -1.),
            v(-1., 2., -1.),
        ],
        white,
    );
    s.add_quad(
        "left",
        [
            v(-1., 0., 1.),
            v(-1., 0., -1.),
            v(-1., 2., -1.),
            v(-1., 2., 1.),
        ],
        red,
    );
    s.add_quad(
        "right",
        [v(1., 0., -1.), v(1., 0., 1.), v(1., 2., 1.), v(1., 2., -1.)],
        green,
    );
    let (bv, bi) = cuboid(v(0.35, 0.3, 0.35), v(0.6, 0.6, 0.6), -0.3);
    s.add_mesh("short-block", bv, bi, white);
    let (bv, bi) = cuboid(v(-0.35, 0.6, -0.3), v(0.6, 1.2, 0.6), 0.3);
    s.add_mesh("tall-block", bv, bi, white);
    s
}
