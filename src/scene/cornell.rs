//! The built-in Cornell box: a 2 m cube open at the front (+z), red left wall,
//! green right wall, two white blocks, and a spot light under the ceiling aimed
//! down and slightly back, which sweeps across the box and back every 4 s
//! ([`SWEEP_PERIOD`]). `assets/cornell.gltf` is this scene written by
//! `isr export-builtin` (a test checks that the two agree).

use super::animation::{
    rotation_looking_along, Animation, Channel, Interpolation, Local, Parent, Property, Trs,
};
use super::{cuboid, Camera, Scene, SpotLight};
use glam::{Mat4, Quat, Vec3, Vec4};

/// Seconds of one sweep of the light, after which it repeats.
pub const SWEEP_PERIOD: f32 = 4.0;

/// How far the light tilts toward each side wall, degrees. At 40 degrees its
/// axis meets the wall 0.7 m above the floor: the spot straddles the corner
/// between wall and floor, close to the light, where light-space sampling is
/// hardest (a depth and normal discontinuity in the RSM, and receivers near
/// their sources).
const SWEEP_TILT_DEG: f32 = 40.0;

pub fn cornell_box() -> Scene {
    let light = SpotLight {
        kind: crate::scene::LightKind::Spot,
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
    s.animation = Some(light_sweep(&light));
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

/// The light turns about the world Z axis through its position: at rest at 0 s,
/// tilted toward the green wall (+x) at 1 s, at rest at 2 s, toward the red
/// wall at 3 s, at rest at 4 s. LINEAR keys, so it sweeps at a constant rate.
fn light_sweep(light: &SpotLight) -> Animation {
    let rest = Trs {
        translation: light.position,
        rotation: rotation_looking_along(light.direction),
        scale: Vec3::ONE,
    };
    let key = |deg: f32| Vec4::from(Quat::from_rotation_z(deg.to_radians()) * rest.rotation);
    let quarter = SWEEP_PERIOD / 4.0;
    let mut a = Animation::default();
    let built_in = "the built-in light sweep is valid";
    let node = a
        .add_node(Parent::Fixed(Mat4::IDENTITY), Local::Animated(rest))
        .expect(built_in);
    a.attach_light(0, node);
    let channel = Channel::new(
        node,
        Property::Rotation,
        Interpolation::Linear,
        (0..5).map(|k| k as f32 * quarter).collect(),
        [0.0, SWEEP_TILT_DEG, 0.0, -SWEEP_TILT_DEG, 0.0]
            .map(key)
            .to_vec(),
    )
    .expect(built_in);
    a.add_channel(channel).expect(built_in);
    a
}
