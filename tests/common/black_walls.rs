//! A scene whose later bounces are exactly zero: the light of the first
//! bounce lands only on black surfaces.

use super::{floor_scene, spot};
use glam::Vec3;
use isr::scene::{Camera, Scene};

/// A grey floor in a box of black walls (albedo 0, open above), a spot on
/// the floor: the floor's light reaches the walls (the first bounce), and
/// nothing reflects it on, since the floor sees only the walls.
pub fn floor_in_black_walls() -> Scene {
    let light = spot(Vec3::new(0.0, 1.5, 0.0), Vec3::ZERO, 4.0, 30.0, 40.0);
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.8, 1.2),
        Vec3::new(0.0, 0.2, -0.3),
        Vec3::Y,
        70f32.to_radians(),
        0.01,
    );
    let mut s = floor_scene(light, camera, 1.0, 0.5);
    let black = s.add_material("black", Vec3::ZERO);
    for inward in [Vec3::X, -Vec3::X, Vec3::Z, -Vec3::Z] {
        // Counter-clockwise seen from inside: along Y x inward, then up.
        let (c, d) = (-inward, Vec3::Y.cross(inward));
        s.add_quad(
            "wall",
            [c - d, c + d, c + d + Vec3::Y, c - d + Vec3::Y],
            black,
        );
    }
    s
}
