//! Direct light against KHR_lights_punctual (docs/algorithm.md sections 2
//! and 2.4), for each kind of light: every lit pixel of a floor matches
//! `rho / pi` times the irradiance the extension's formulas give (written out
//! in `common`, not taken from the library) within 1%, including the spot's
//! smooth cone edge and a point light's range window; a point behind an
//! occluder is dark and the points beside it are lit within 1%.
mod common;

use common::*;
use glam::{DVec3, Vec3};
use isr::scene::{Camera, Light, LightKind, Scene};

/// The floor each kind is checked on, seen by `camera`, and the least number
/// of pixels that must be checked.
struct Plane {
    light: Light,
    camera: Camera,
    size: u32,
    min_checked: usize,
    /// The number of pixels in the spot's smooth edge or the range window's
    /// fall must be more than this, where there is one.
    min_in_ramp: Option<usize>,
}

fn plane(kind: LightKind) -> Plane {
    match kind {
        LightKind::Spot => Plane {
            light: spot(
                Vec3::new(0.5, 2.0, -0.3),
                Vec3::new(1.5, 0.0, -0.5),
                10.0,
                25.0,
                40.0,
            ),
            camera: Camera::look_at(
                Vec3::new(1.0, 6.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                -Vec3::Z,
                70f32.to_radians(),
                0.1,
            ),
            size: 256,
            min_checked: 5000,
            min_in_ramp: Some(500),
        },
        // Every cube face but +y sees part of the floor: the faces' seams
        // cross it.
        LightKind::Point => Plane {
            light: point(Vec3::new(0.3, 1.2, -0.2), 7.0),
            camera: looking_down(),
            size: 192,
            min_checked: 20000,
            min_in_ramp: None,
        },
        LightKind::Directional => Plane {
            light: sun(Vec3::new(0.3, -1.0, 0.2), 2.5),
            camera: looking_down(),
            size: 192,
            min_checked: 20000,
            min_in_ramp: None,
        },
    }
}

/// Every floor pixel whose light is above 1e-3 of the unattenuated value
/// against the formula, enough of them, and enough in the spot's smooth edge
/// or the range window's fall (attenuation 0.05 to 0.95).
fn floor_matches(p: &Plane) {
    let gpu = gpu();
    let albedo = 0.6;
    let scene = floor_scene(p.light, p.camera, 4.0, albedo as f32);
    let out = render(&gpu, &scene, &sized("none", p.size, p.size, 1024), 1).readback;
    let light = &p.light;
    let (mut checked, mut in_ramp, mut worst) = (0, 0, 0f64);
    for (i, (pos, direct)) in out.position.iter().zip(&out.direct).enumerate() {
        if pos[3] <= 0.0 {
            continue;
        }
        let x = dvec(pos);
        let expected = expected_direct(light, albedo, x, DVec3::Y);
        let att = khr_attenuation(light, x);
        if att < 1e-3 || expected.x <= 0.0 {
            continue;
        }
        let got = dvec(direct);
        let rel = ((got - expected).abs() / expected).max_element();
        assert!(
            rel < 0.01,
            "{:?} light, pixel ({}, {}) at {x:?}: direct {got:?} vs formula {expected:?} \
             (attenuation {att:.3}, relative error {rel:.4})",
            light.kind,
            i as u32 % out.width,
            i as u32 / out.width
        );
        worst = worst.max(rel);
        checked += 1;
        in_ramp += (0.05..0.95).contains(&att) as usize;
    }
    println!(
        "{:?}: checked {checked} pixels ({in_ramp} in a smooth edge), worst relative error {worst:.2e}",
        light.kind
    );
    assert!(
        checked > p.min_checked,
        "{:?}: too few lit pixels checked: {checked}",
        light.kind
    );
    assert!(
        p.min_in_ramp.is_none_or(|min| in_ramp > min),
        "{:?}: too few pixels in the attenuation's fall: {in_ramp}",
        light.kind
    );
}

fn floor_matches_the_formula(kind: LightKind) {
    floor_matches(&plane(kind));
}

light_kind_tests!(floor_matches_the_formula:
    spot_light_on_a_plane_matches_the_formula_including_the_cone_edge,
    point_light_on_a_plane_matches_i_cos_over_d_squared,
    directional_light_on_a_plane_matches_e_cos);

/// A range of 2.5 m: the window `1 - (d / range)^4` falls across the floor.
#[test]
fn point_light_with_a_range_matches_the_range_window() {
    let mut p = plane(LightKind::Point);
    p.light.range = Some(2.5);
    p.min_checked = 5000;
    p.min_in_ramp = Some(1000);
    floor_matches(&p);
}

/// The shadow test of each kind: the scene, the floor points the occluder
/// shadows and the points beside it, and how dark a shadowed point must be
/// (a fraction of its unshadowed light).
struct Shadow {
    scene: Scene,
    size: u32,
    shadowed: Vec<Vec3>,
    lit: Vec<Vec3>,
    dark: f64,
}

fn shadow(kind: LightKind) -> Shadow {
    // The point and directional lights' occluder: a square of half-size 0.3
    // facing up at `c`, over a floor seen from above.
    let c = Vec3::new(1.0, 0.5, 0.5);
    let from_above = |light: Light, shadowed| {
        let mut scene = floor_scene(light, looking_down(), 4.0, 0.6);
        add_square(&mut scene, "occluder", c, 0.3, 0.5);
        Shadow {
            scene,
            size: 192,
            shadowed: vec![shadowed],
            lit: vec![Vec3::new(-1.5, 0.0, -1.5)],
            dark: 0.01,
        }
    };
    match kind {
        LightKind::Spot => {
            let scene = spot_over_an_occluder(true);
            Shadow {
                scene,
                size: 256,
                shadowed: vec![
                    Vec3::new(0.0, 0.0, 0.0),
                    Vec3::new(0.25, 0.0, -0.2),
                    Vec3::new(-0.3, 0.0, 0.3),
                ],
                lit: vec![
                    Vec3::new(1.0, 0.0, 0.0),
                    Vec3::new(-0.8, 0.0, 0.6),
                    Vec3::new(0.0, 0.0, 0.7),
                ],
                dark: 1e-3,
            }
        }
        // The occluder's centre seen from the light lands at
        // light + 1.2 / 0.7 (centre - light) on the floor.
        LightKind::Point => {
            let light = point(Vec3::new(0.3, 1.2, -0.2), 7.0);
            from_above(light, light.position + (c - light.position) * (1.2 / 0.7))
        }
        // 45 degrees: the shadow is the square shifted by 0.5 along x.
        LightKind::Directional => from_above(
            sun(Vec3::new(1.0, -1.0, 0.0), 2.0),
            Vec3::new(1.5, 0.0, 0.5),
        ),
    }
}

/// The shadowed floor points are dark and the points beside them are lit
/// within 1% of the formula.
fn occluder_shadows_the_floor(kind: LightKind) {
    let gpu = gpu();
    let case = shadow(kind);
    let light = case.scene.lights[0];
    let size = case.size;
    let rendered = render(&gpu, &case.scene, &sized("none", size, size, 512), 1);
    let out = &rendered.readback;
    let albedo = case.scene.materials[0].base_color.x as f64;
    let points =
        (case.shadowed.iter().map(|&p| (p, false))).chain(case.lit.iter().map(|&p| (p, true)));
    for (at, lit) in points {
        let (x, y) = project(&rendered, at).expect("on screen");
        let i = (y * size + x) as usize;
        let p = dvec(&out.position[i]);
        assert!(
            out.position[i][3] > 0.0 && p.y.abs() < 1e-3,
            "{kind:?}: pixel ({x}, {y}) sees the floor, not {p:?}"
        );
        let formula = expected_direct(&light, albedo, p, DVec3::Y).x;
        let got = out.direct[i][0] as f64;
        if lit {
            assert!(
                ((got - formula) / formula).abs() < 0.01,
                "{kind:?}: lit point {p:?}: {got} vs {formula}"
            );
        } else {
            assert!(
                got < case.dark * formula,
                "{kind:?}: shadowed point {p:?}: {got} (unshadowed {formula})"
            );
        }
    }
}

light_kind_tests!(occluder_shadows_the_floor:
    a_spot_light_casts_a_shadow,
    a_point_light_casts_a_shadow,
    a_directional_light_casts_a_shadow);
