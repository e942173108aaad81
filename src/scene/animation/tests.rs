use super::*;
use crate::scene::{Camera, SpotLight};
use std::f32::consts::FRAC_PI_2;

fn v3(x: f32, y: f32, z: f32) -> Vec4 {
    Vec4::new(x, y, z, 0.0)
}

fn channel(p: Property, i: Interpolation, times: &[f32], values: &[Vec4]) -> Channel {
    Channel::new(0, p, i, times.to_vec(), values.to_vec()).unwrap()
}

/// Equal as rotations: q and -q are the same one.
fn same_rotation(a: Vec4, b: Vec4) -> bool {
    a.abs_diff_eq(b, 1e-6) || a.abs_diff_eq(-b, 1e-6)
}

#[test]
fn step_holds_each_key_until_the_next() {
    let vals = [v3(1., 0., 0.), v3(2., 0., 0.), v3(3., 0., 0.)];
    let c = channel(
        Property::Translation,
        Interpolation::Step,
        &[0.5, 1.0, 3.0],
        &vals,
    );
    for (t, want) in [
        (-2.0, 0), // before the first key: clamped
        (0.5, 0),
        (0.99, 0),
        (1.0, 1), // at a key: that key
        (2.9, 1),
        (3.0, 2),
        (100.0, 2), // after the last key: clamped
    ] {
        assert_eq!(c.sample(t), vals[want], "t {t}");
    }
    assert_eq!(c.end(), 3.0);
}

#[test]
fn linear_translation_interpolates_and_clamps() {
    let c = channel(
        Property::Translation,
        Interpolation::Linear,
        &[1.0, 3.0, 4.0],
        &[v3(0., 0., 0.), v3(2., 4., -6.), v3(0., 0., 0.)],
    );
    // A quarter of the way from 1 s to 3 s.
    assert!(c.sample(1.5).abs_diff_eq(v3(0.5, 1.0, -1.5), 1e-6));
    // Half way from 3 s to 4 s.
    assert!(c.sample(3.5).abs_diff_eq(v3(1.0, 2.0, -3.0), 1e-6));
    assert_eq!(c.sample(0.0), v3(0., 0., 0.));
    assert_eq!(c.sample(3.0), v3(2., 4., -6.));
    assert_eq!(c.sample(9.0), v3(0., 0., 0.));
}

#[test]
fn slerp_takes_the_shorter_arc_across_the_double_cover() {
    let q = |deg: f32| Vec4::from(Quat::from_rotation_y(deg.to_radians()));
    // (0, sin(a/2), 0, cos(a/2)) for a rotation by a about +Y.
    let by_hand = |deg: f32| {
        let h = (deg / 2.0).to_radians();
        Vec4::new(0.0, h.sin(), 0.0, h.cos())
    };
    let c = channel(
        Property::Rotation,
        Interpolation::Linear,
        &[0.0, 2.0],
        &[q(0.0), q(90.0)],
    );
    assert!(c.sample(1.0).abs_diff_eq(by_hand(45.0), 1e-6));
    assert!(c.sample(0.5).abs_diff_eq(by_hand(22.5), 1e-6));
    // The second key given as -q: the same rotation, and the same path
    // (not the long way round through 225 degrees).
    let c = channel(
        Property::Rotation,
        Interpolation::Linear,
        &[0.0, 2.0],
        &[q(0.0), -q(90.0)],
    );
    assert!(same_rotation(c.sample(1.0), by_hand(45.0)));
    assert!(same_rotation(c.sample(0.5), by_hand(22.5)));
    // From 170 to -170 degrees is 20 degrees through 180, not 340 back
    // through 0 (the keys' dot product is negative).
    let c = channel(
        Property::Rotation,
        Interpolation::Linear,
        &[0.0, 1.0],
        &[q(170.0), q(-170.0)],
    );
    assert!(q(170.0).dot(q(-170.0)) < 0.0);
    assert!(same_rotation(c.sample(0.5), by_hand(180.0)));
    assert!(same_rotation(c.sample(0.25), by_hand(175.0)));
    // Keys that are not quite unit are normalized first.
    let c = channel(
        Property::Rotation,
        Interpolation::Step,
        &[0.0],
        &[Vec4::new(0.0, 0.0, 0.0, 2.0)],
    );
    assert_eq!(c.sample(0.0), Vec4::W);
}

#[test]
fn cubic_spline_with_unequal_intervals_matches_hermite_by_hand() {
    // Keys at 0, 1 and 3 s (intervals 1 and 2); each key is in-tangent,
    // value, out-tangent.
    let c = channel(
        Property::Translation,
        Interpolation::CubicSpline,
        &[0.0, 1.0, 3.0],
        &[
            v3(9., 9., 9.),
            v3(0., 0., 0.),
            v3(2., 0., 0.),
            v3(0., 1., 0.),
            v3(1., 0., 0.),
            v3(0., 2., 0.),
            v3(0., 0., 4.),
            v3(3., 0., 0.),
            v3(9., 9., 9.),
        ],
    );
    // t = 2 s: s = 0.5 in [1, 3], dt = 2. Hermite basis at 0.5:
    // h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125, so
    // p = 0.5 (1,0,0) + 0.125*2 (0,2,0) + 0.5 (3,0,0) - 0.125*2 (0,0,4).
    assert!(c.sample(2.0).abs_diff_eq(v3(2.0, 0.5, -1.0), 1e-6));
    // t = 0.25 s: s = 0.25 in [0, 1], dt = 1. h00 = 0.84375,
    // h10 = 0.140625, h01 = 0.15625, h11 = -0.046875:
    // p = 0.140625 (2,0,0) + 0.15625 (1,0,0) - 0.046875 (0,1,0).
    assert!(c.sample(0.25).abs_diff_eq(v3(0.4375, -0.046875, 0.0), 1e-6));
    // t = 2.5 s: s = 0.75, dt = 2. h00 = 0.15625, h10 = 0.046875,
    // h01 = 0.84375, h11 = -0.140625:
    // p = 0.15625 (1,0,0) + 0.09375 (0,2,0) + 0.84375 (3,0,0) - 0.28125 (0,0,4).
    assert!(c.sample(2.5).abs_diff_eq(v3(2.6875, 0.1875, -1.125), 1e-6));
    // At keys and outside them: the values, never the tangents.
    assert_eq!(c.sample(1.0), v3(1., 0., 0.));
    assert_eq!(c.sample(-1.0), v3(0., 0., 0.));
    assert_eq!(c.sample(5.0), v3(3., 0., 0.));
}

#[test]
fn cubic_spline_rotations_are_normalized() {
    let q0 = Vec4::from(Quat::IDENTITY);
    let q1 = Vec4::from(Quat::from_rotation_z(FRAC_PI_2));
    let c = channel(
        Property::Rotation,
        Interpolation::CubicSpline,
        &[0.0, 2.0],
        &[Vec4::ZERO, q0, Vec4::ZERO, Vec4::ZERO, q1, Vec4::ZERO],
    );
    // Zero tangents: h00 q0 + h01 q1 with h00 = h01 = 0.5 at s = 0.5.
    let want = ((q0 + q1) * 0.5).normalize();
    assert!(c.sample(1.0).abs_diff_eq(want, 1e-6));
    assert!((c.sample(0.7).length() - 1.0).abs() < 1e-6);
}

#[test]
fn bad_keys_are_refused() {
    let t = Property::Translation;
    let new = |i, times: &[f32], n: usize| {
        Channel::new(0, t, i, times.to_vec(), vec![Vec4::ZERO; n]).unwrap_err()
    };
    let e = new(Interpolation::Linear, &[0.0, 1.0, 2.0], 2);
    assert!(
        e.contains("3 keyframe times") && e.contains("2 values"),
        "{e}"
    );
    let e = new(Interpolation::CubicSpline, &[0.0, 1.0], 4);
    assert!(
        e.contains("CUBICSPLINE") && e.contains("three per time"),
        "{e}"
    );
    let e = new(Interpolation::Step, &[0.0, 1.0, 1.0], 3);
    assert!(
        e.contains("increase strictly") && e.contains("time 2"),
        "{e}"
    );
    let e = new(Interpolation::Step, &[0.0, f32::NAN], 2);
    assert!(e.contains("time 1 is NaN"), "{e}");
    let e = new(Interpolation::Step, &[], 0);
    assert!(e.contains("no keyframes"), "{e}");
    let e = Channel::new(
        0,
        t,
        Interpolation::Step,
        vec![0.0],
        vec![Vec4::splat(f32::INFINITY)],
    )
    .unwrap_err();
    assert!(e.contains("not finite"), "{e}");
    let e = Channel::new(
        0,
        Property::Rotation,
        Interpolation::Step,
        vec![0.0],
        vec![Vec4::ZERO],
    )
    .unwrap_err();
    assert!(e.contains("zero quaternion"), "{e}");
}

fn state(instances: usize) -> FrameState {
    FrameState {
        camera: Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 0.7, 0.05),
        lights: vec![SpotLight {
            kind: crate::scene::LightKind::Spot,
            position: Vec3::ZERO,
            direction: -Vec3::Y,
            color: Vec3::ONE,
            intensity: 1.0,
            inner_cone: 0.3,
            outer_cone: 0.6,
            range: None,
        }],
        instance_transforms: vec![Mat4::IDENTITY; instances],
    }
}

#[test]
fn nested_nodes_compose_parent_then_child() {
    let lift = Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0));
    let mut a = Animation::default();
    // parent: rotates about +Y from 0 to 90 degrees over 1 s, under a
    // static lift; child: translates from (1,0,0) to (1,0,2) over 2 s and
    // carries instance 1; a static offset below the child carries the
    // camera; the light hangs on the parent.
    let parent = a
        .add_node(
            Parent::Fixed(lift),
            Local::Animated(Trs {
                translation: Vec3::ZERO,
                rotation: Quat::IDENTITY,
                scale: Vec3::ONE,
            }),
        )
        .unwrap();
    let child = a
        .add_node(
            Parent::Node(parent),
            Local::Animated(Trs {
                translation: Vec3::X,
                rotation: Quat::IDENTITY,
                scale: Vec3::splat(2.0),
            }),
        )
        .unwrap();
    let offset = Mat4::from_translation(Vec3::new(0.0, 0.0, 0.5));
    let below = a
        .add_node(Parent::Node(child), Local::Fixed(offset))
        .unwrap();
    let spin = [Quat::IDENTITY, Quat::from_rotation_y(FRAC_PI_2)].map(Vec4::from);
    a.add_channel(
        Channel::new(
            parent,
            Property::Rotation,
            Interpolation::Linear,
            vec![0.0, 1.0],
            spin.to_vec(),
        )
        .unwrap(),
    )
    .unwrap();
    a.add_channel(
        Channel::new(
            child,
            Property::Translation,
            Interpolation::Linear,
            vec![0.0, 2.0],
            vec![v3(1., 0., 0.), v3(1., 0., 2.)],
        )
        .unwrap(),
    )
    .unwrap();
    a.attach_instance(1, child);
    a.attach_camera(below);
    a.attach_light(0, parent);
    assert_eq!(a.duration(), Some(2.0));

    let mut s = state(3);
    a.apply(0.5, &mut s);
    // Parent at 0.5 s: 45 degrees about +Y; child: (1, 0, 0.5), scale 2.
    let (sn, c) = (FRAC_PI_2 / 2.0).sin_cos();
    #[rustfmt::skip]
    let parent_m = Mat4::from_cols_array(&[
        c, 0.0, -sn, 0.0,
        0.0, 1.0, 0.0, 0.0,
        sn, 0.0, c, 0.0,
        0.0, 2.0, 0.0, 1.0,
    ]);
    #[rustfmt::skip]
    let child_m = Mat4::from_cols_array(&[
        2.0, 0.0, 0.0, 0.0,
        0.0, 2.0, 0.0, 0.0,
        0.0, 0.0, 2.0, 0.0,
        1.0, 0.0, 0.5, 1.0,
    ]);
    assert!(s.instance_transforms[1].abs_diff_eq(parent_m * child_m, 1e-6));
    // Instances no node carries stay put.
    assert_eq!(s.instance_transforms[0], Mat4::IDENTITY);
    assert_eq!(s.instance_transforms[2], Mat4::IDENTITY);
    // The camera where its node is, without the node's scale of 2 (its
    // field of view and znear are its own).
    let node = parent_m * child_m * offset;
    let rigid = Mat4::from_cols(
        node.x_axis / 2.0,
        node.y_axis / 2.0,
        node.z_axis / 2.0,
        node.w_axis,
    );
    assert!(s.camera.world_from_camera.abs_diff_eq(rigid, 1e-6));
    // The light at the parent's origin, pointing along its -Z.
    assert!(s.lights[0]
        .position
        .abs_diff_eq(Vec3::new(0.0, 2.0, 0.0), 1e-6));
    assert!(s.lights[0]
        .direction
        .abs_diff_eq(Vec3::new(-sn, 0.0, -c), 1e-6));
}

#[test]
fn channels_need_an_animated_node() {
    let mut a = Animation::default();
    let n = a
        .add_node(Parent::Fixed(Mat4::IDENTITY), Local::Fixed(Mat4::IDENTITY))
        .unwrap();
    let c = Channel::new(
        n,
        Property::Scale,
        Interpolation::Step,
        vec![0.0],
        vec![Vec4::ONE],
    )
    .unwrap();
    assert!(a.add_channel(c.clone()).is_err());
    assert!(a
        .add_node(Parent::Node(3), Local::Fixed(Mat4::IDENTITY))
        .is_err());
    assert_eq!(a.duration(), None);
}

#[test]
fn looking_along_points_minus_z_along_the_direction() {
    for d in [
        Vec3::new(0.0, -1.0, -0.15),
        Vec3::new(1.0, 0.2, 0.0),
        -Vec3::Y,
        Vec3::Z,
    ] {
        let q = rotation_looking_along(d);
        assert!((q * -Vec3::Z).abs_diff_eq(d.normalize(), 1e-6), "{d}");
        assert!(q.is_normalized());
    }
    // Level: the node's x axis stays horizontal.
    let q = rotation_looking_along(Vec3::new(0.3, -1.0, -0.2));
    assert!((q * Vec3::X).y.abs() < 1e-6);
}
