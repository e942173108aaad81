//! Direct light against docs/algorithm.md section 2, and the shadow test.
mod common;

use common::*;
use glam::{DVec3, Vec3, Vec4};
use isr::scene::Camera;
use isr::settings::{Method, RenderSettings};

#[test]
fn plane_lit_by_spot_matches_formula_including_cone_edge() {
    let gpu = gpu();
    let light = spot(
        Vec3::new(0.5, 2.0, -0.3),
        Vec3::new(1.5, 0.0, -0.5),
        10.0,
        25.0,
        40.0,
    );
    let camera = Camera::look_at(
        Vec3::new(1.0, 6.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        -Vec3::Z,
        70f32.to_radians(),
        0.1,
    );
    let albedo = 0.6;
    let scene = floor_scene(light, camera, 4.0, albedo);
    let settings = RenderSettings {
        width: 256,
        height: 256,
        rsm_resolution: 1024,
        method: Method::new("none"),
        ..Default::default()
    };
    let out = render(&gpu, &scene, &settings, 1).readback;

    let mut checked = 0;
    let mut in_ramp = 0;
    let mut worst: f64 = 0.0;
    for (i, (pos, direct)) in out.position.iter().zip(&out.direct).enumerate() {
        if pos[3] <= 0.0 {
            continue;
        }
        let p = DVec3::new(pos[0] as f64, pos[1] as f64, pos[2] as f64);
        let att = light.intensity_toward(p).x / light.intensity as f64;
        if att < 1e-3 {
            continue;
        }
        let expected = expected_direct(&light, Vec4::splat(albedo), p, DVec3::Y);
        let got = DVec3::new(direct[0] as f64, direct[1] as f64, direct[2] as f64);
        let rel = ((got - expected).abs() / expected).max_element();
        assert!(
            rel < 0.01,
            "pixel {} ({}, {}): direct {got:?} vs formula {expected:?} (attenuation {att:.3}, relative error {rel:.4})",
            i,
            i as u32 % out.width,
            i as u32 / out.width
        );
        worst = worst.max(rel);
        checked += 1;
        if (0.05..0.95).contains(&att) {
            in_ramp += 1;
        }
    }
    println!("checked {checked} pixels ({in_ramp} in the cone's smooth edge), worst relative error {worst:.2e}");
    assert!(checked > 5000, "too few lit pixels checked: {checked}");
    assert!(
        in_ramp > 500,
        "too few pixels near the cone edge: {in_ramp}"
    );
}

#[test]
fn point_behind_occluder_is_in_shadow_and_point_beside_it_is_lit() {
    let gpu = gpu();
    let light = spot(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, 10.0, 40.0, 50.0);
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.5, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        50f32.to_radians(),
        0.1,
    );
    let mut scene = floor_scene(light, camera, 3.0, 0.5);
    let m = scene.add_material("occluder", Vec3::splat(0.5));
    let v = Vec3::new;
    // Faces up, toward the light; half-size 0.2 at height 1 shadows |x|,|z| < 0.4 on the floor.
    scene.add_quad(
        "occluder",
        [
            v(-0.2, 1., 0.2),
            v(0.2, 1., 0.2),
            v(0.2, 1., -0.2),
            v(-0.2, 1., -0.2),
        ],
        m,
    );
    let settings = RenderSettings {
        width: 256,
        height: 256,
        rsm_resolution: 512,
        method: Method::new("none"),
        ..Default::default()
    };
    let out = render(&gpu, &scene, &settings, 1);
    let rb = &out.readback;
    let at = |p: Vec3| {
        let (x, y) = project(&out.uniforms, rb.width, rb.height, p).expect("point on screen");
        let i = (y * rb.width + x) as usize;
        let pos = rb.position[i];
        assert!(
            pos[3] > 0.0 && pos[1].abs() < 1e-3,
            "pixel of {p} does not see the floor: {pos:?}"
        );
        let world = DVec3::new(pos[0] as f64, pos[1] as f64, pos[2] as f64);
        (
            rb.direct[i][0] as f64,
            expected_direct(&light, Vec4::splat(0.5), world, DVec3::Y).x,
        )
    };
    for p in [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.25, 0.0, -0.2),
        Vec3::new(-0.3, 0.0, 0.3),
    ] {
        let (got, unshadowed) = at(p);
        assert!(
            got < 1e-3 * unshadowed,
            "{p} is behind the occluder but has direct {got} (unshadowed {unshadowed})"
        );
    }
    for p in [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(-0.8, 0.0, 0.6),
        Vec3::new(0.0, 0.0, 0.7),
    ] {
        let (got, unshadowed) = at(p);
        assert!(
            (got - unshadowed).abs() < 0.01 * unshadowed,
            "{p} is in the open but has direct {got}, expected {unshadowed}"
        );
    }
}
