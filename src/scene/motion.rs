//! Built-in motion for scenes without animation (`--orbit-light`,
//! `--orbit-camera`): pure functions of a frame's state and the time.
//!
//! Both circle the scene's vertical axis, the line along +Y through the
//! `pivot` (the centre of the scene's bounds, [`pivot`]), counter-clockwise
//! seen from above, one turn per `period` seconds, starting (t = 0) where the
//! state has them. Radius and height stay those of the starting position.
//!
//! Each keeps aiming at one fixed *aim point*: the point of its initial axis
//! (the light's direction, the camera's forward) nearest the pivot. For a
//! camera looking at the scene that is the point it looks at; for a light hung
//! above the scene and aimed down it is (close to) where its axis meets the
//! scene's centre height. When the axis points away from the pivot, the aim
//! point lies ahead at the pivot's distance.

use super::animation::rotation_looking_along;
use super::{FrameState, Scene};
use glam::{Mat3, Mat4, Quat, Vec3};

/// The centre of the scene's bounds (the origin for an empty scene).
pub fn pivot(scene: &Scene) -> Vec3 {
    scene
        .bounds()
        .map_or(Vec3::ZERO, |(lo, hi)| (lo + hi) * 0.5)
}

/// The point of the ray `position + s * direction` (s > 0) nearest `pivot`; at
/// the pivot's distance when the ray points away from it.
pub fn aim_point(position: Vec3, direction: Vec3, pivot: Vec3) -> Vec3 {
    let d = direction.normalize();
    let to = pivot - position;
    let along = to.dot(d);
    let s = if along > 1e-3 * to.length() {
        along
    } else {
        to.length().max(1e-3)
    };
    position + d * s
}

/// The turn about +Y at time `t`; `None` for a zero or non-finite period.
fn turn(period: f32, t: f32) -> Option<Quat> {
    // The fraction first, so that late times keep their precision.
    let turns = (t / period).rem_euclid(1.0);
    turns
        .is_finite()
        .then(|| Quat::from_rotation_y(std::f32::consts::TAU * turns))
}

/// Moves the lights of `state` (their placement at t = 0) to time `t` of
/// their orbit, each aimed at its aim point (a directional light turns).
pub fn orbit_light(state: &mut FrameState, pivot: Vec3, period: f32, t: f32) {
    let Some(rot) = turn(period, t) else { return };
    for l in &mut state.lights {
        let aim = aim_point(l.position, l.direction, pivot);
        l.position = pivot + rot * (l.position - pivot);
        l.direction = (aim - l.position).normalize_or(rot * l.direction);
    }
}

/// Moves the camera of `state` (its placement at t = 0) to time `t` of its
/// orbit, looking at its aim point; a level camera stays level.
pub fn orbit_camera(state: &mut FrameState, pivot: Vec3, period: f32, t: f32) {
    let Some(rot) = turn(period, t) else { return };
    let c = &mut state.camera;
    let (position, forward) = (c.position(), c.forward());
    let aim = aim_point(position, forward, pivot);
    let position = pivot + rot * (position - pivot);
    let new_forward = (aim - position).normalize_or(rot * forward);
    // From the old look-at frame (forward, +Y up) to the new one: the camera's
    // roll about its forward axis, relative to level, is kept.
    let turn = rotation_looking_along(new_forward) * rotation_looking_along(forward).inverse();
    let linear = Mat3::from_quat(turn) * Mat3::from_mat4(c.world_from_camera);
    c.world_from_camera = Mat4::from_translation(position) * Mat4::from_mat3(linear);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, SpotLight};

    fn state(light_at: Vec3, light_dir: Vec3, eye: Vec3, target: Vec3) -> FrameState {
        FrameState {
            camera: Camera::look_at(eye, target, Vec3::Y, 0.7, 0.05),
            lights: vec![SpotLight {
                kind: crate::scene::LightKind::Spot,
                position: light_at,
                direction: light_dir.normalize(),
                color: Vec3::ONE,
                intensity: 1.0,
                inner_cone: 0.3,
                outer_cone: 0.6,
                range: None,
            }],
            instance_transforms: vec![],
        }
    }

    /// Distance from `p` to the ray from `o` along `d`.
    fn off_ray(p: Vec3, o: Vec3, d: Vec3) -> f32 {
        let s = (p - o).dot(d);
        assert!(s > 0.0, "the point lies behind");
        (p - (o + d * s)).length()
    }

    fn radius_height(p: Vec3, pivot: Vec3) -> (f32, f32) {
        ((p - pivot).with_y(0.0).length(), p.y)
    }

    #[test]
    fn light_orbits_the_vertical_axis_aimed_at_the_same_point() {
        let pivot = Vec3::new(0.5, 1.0, -0.5);
        let s0 = state(
            Vec3::new(1.5, 2.0, -0.5),
            Vec3::new(-0.3, -1.0, 0.2),
            Vec3::new(0.0, 1.0, 4.0),
            pivot,
        );
        let l0 = s0.lights[0];
        let aim = aim_point(l0.position, l0.direction, pivot);
        // The point of the axis nearest the pivot, by hand.
        let s = (pivot - l0.position).dot(l0.direction);
        assert!(aim.abs_diff_eq(l0.position + l0.direction * s, 1e-6));
        let period = 4.0;
        for t in [0.0, 0.3, 1.0, 2.0, 3.7, 4.0, 9.0] {
            let mut st = s0.clone();
            orbit_light(&mut st, pivot, period, t);
            let l = st.lights[0];
            let (r0, h0) = radius_height(l0.position, pivot);
            let (r, h) = radius_height(l.position, pivot);
            assert!((r - r0).abs() < 1e-5 && (h - h0).abs() < 1e-6, "t {t}");
            // The angle travelled about +Y, counter-clockwise from above.
            let a0 = (l0.position - pivot).with_y(0.0);
            let a = (l.position - pivot).with_y(0.0);
            let turned = Quat::from_rotation_y(std::f32::consts::TAU * t / period) * a0;
            assert!(a.abs_diff_eq(turned, 1e-5), "t {t}: {a} vs {turned}");
            assert!(off_ray(aim, l.position, l.direction) < 1e-5, "t {t}");
            assert!((l.direction.length() - 1.0).abs() < 1e-6);
            // Nothing else changes.
            assert_eq!(
                (l.color, l.intensity, l.inner_cone, l.outer_cone),
                (l0.color, l0.intensity, l0.inner_cone, l0.outer_cone)
            );
            assert_eq!(st.camera, s0.camera);
        }
        // A whole period comes back to the start; half a period is opposite.
        let mut st = s0.clone();
        orbit_light(&mut st, pivot, period, period);
        assert!(st.lights[0].position.abs_diff_eq(l0.position, 1e-5));
        assert!(st.lights[0].direction.abs_diff_eq(l0.direction, 1e-5));
        let mut st = s0.clone();
        orbit_light(&mut st, pivot, period, 0.5 * period);
        assert!(st.lights[0]
            .position
            .abs_diff_eq(Vec3::new(-0.5, 2.0, -0.5), 1e-5));
    }

    #[test]
    fn light_on_the_axis_stays_put() {
        // A light right above the pivot (the built-in box's) has radius 0; its
        // aim point is on its own axis, so it keeps its direction too.
        let pivot = Vec3::new(0.0, 1.0, 0.0);
        let s0 = state(
            Vec3::new(0.0, 1.9, 0.0),
            Vec3::new(0.0, -1.0, -0.15),
            Vec3::new(0.0, 1.0, 3.4),
            pivot,
        );
        let mut st = s0.clone();
        orbit_light(&mut st, pivot, 4.0, 1.0);
        assert!(st.lights[0]
            .position
            .abs_diff_eq(s0.lights[0].position, 1e-6));
        assert!(st.lights[0]
            .direction
            .abs_diff_eq(s0.lights[0].direction, 1e-6));
    }

    #[test]
    fn camera_orbits_looking_at_the_same_target_and_stays_level() {
        let pivot = Vec3::new(0.0, 1.0, 0.0);
        let target = Vec3::new(0.2, 0.8, 0.1);
        let eye = Vec3::new(0.5, 1.6, 3.0);
        let s0 = state(Vec3::new(0.0, 1.9, 0.0), -Vec3::Y, eye, target);
        let aim = aim_point(eye, s0.camera.forward(), pivot);
        let period = 6.0;
        for t in [0.0, 0.5, 1.5, 3.0, 4.5, 6.0, 13.0] {
            let mut st = s0.clone();
            orbit_camera(&mut st, pivot, period, t);
            let c = st.camera;
            let (r0, h0) = radius_height(eye, pivot);
            let (r, h) = radius_height(c.position(), pivot);
            assert!((r - r0).abs() < 1e-5 && (h - h0).abs() < 1e-5, "t {t}");
            let a0 = (eye - pivot).with_y(0.0);
            let turned = Quat::from_rotation_y(std::f32::consts::TAU * t / period) * a0;
            assert!(
                (c.position() - pivot).with_y(0.0).abs_diff_eq(turned, 1e-5),
                "t {t}"
            );
            assert!(off_ray(aim, c.position(), c.forward()) < 1e-5, "t {t}");
            // Level: the camera's x axis stays horizontal, its y axis up.
            let x = c.world_from_camera.x_axis.truncate();
            let y = c.world_from_camera.y_axis.truncate();
            assert!(x.y.abs() < 1e-5 && y.y > 0.0, "t {t}: x {x}");
            assert!((x.length() - 1.0).abs() < 1e-5 && x.dot(y).abs() < 1e-5);
            assert_eq!((c.yfov, c.znear), (s0.camera.yfov, s0.camera.znear));
            assert_eq!(st.lights[0], s0.lights[0]);
        }
        let mut st = s0.clone();
        orbit_camera(&mut st, pivot, period, period);
        assert!(st
            .camera
            .world_from_camera
            .abs_diff_eq(s0.camera.world_from_camera, 1e-5));
    }

    #[test]
    fn zero_period_leaves_the_state_alone() {
        let s0 = state(Vec3::ONE, -Vec3::Y, Vec3::Z * 3.0, Vec3::ZERO);
        let mut st = s0.clone();
        orbit_light(&mut st, Vec3::ZERO, 0.0, 1.0);
        orbit_camera(&mut st, Vec3::ZERO, f32::NAN, 1.0);
        assert_eq!(st, s0);
    }
}
