//! Point and directional lights, and several lights at once
//! (docs/algorithm.md section 2.4): direct light against the formulas, shadows,
//! RSM energy, sums of lights, HISR convergence.
mod common;

use common::*;
use glam::{DVec3, Vec3};
use isr::methods::{hisr, isr::BASE, reference, vpls::VPLS};
use isr::renderer::Renderer;
use isr::scene::{cornell::cornell_box, Camera, Light, LightKind, Scene};
use isr::settings::{Method, RenderSettings};

fn point(position: Vec3, intensity: f32) -> Light {
    Light {
        kind: LightKind::Point,
        position,
        direction: -Vec3::Y,
        color: Vec3::ONE,
        intensity,
        inner_cone: 0.0,
        outer_cone: std::f32::consts::FRAC_PI_2,
        range: None,
    }
}

fn sun(direction: Vec3, irradiance: f32) -> Light {
    Light {
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: direction.normalize(),
        color: Vec3::ONE,
        intensity: irradiance,
        inner_cone: 0.0,
        outer_cone: std::f32::consts::FRAC_PI_2,
        range: None,
    }
}

fn looking_down() -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 6.0, 0.0),
        Vec3::ZERO,
        -Vec3::Z,
        70f32.to_radians(),
        0.1,
    )
}

/// A floor and, when `occluder` is set, a square of half-size 0.3 facing up
/// at that centre.
fn floor_with(light: Light, albedo: f32, occluder: Option<Vec3>) -> Scene {
    let mut s = floor_scene(light, looking_down(), 4.0, albedo);
    if let Some(c) = occluder {
        let m = s.add_material("occluder", Vec3::splat(0.5));
        let h = 0.3;
        s.add_quad(
            "occluder",
            [
                c + Vec3::new(-h, 0.0, h),
                c + Vec3::new(h, 0.0, h),
                c + Vec3::new(h, 0.0, -h),
                c + Vec3::new(-h, 0.0, -h),
            ],
            m,
        );
    }
    s
}

fn direct_only(width: u32, rsm: u32) -> RenderSettings {
    RenderSettings {
        width,
        height: width,
        rsm_resolution: rsm,
        method: Method::new("none"),
        ..Default::default()
    }
}

/// Every floor pixel against `expected` (rho/pi times the irradiance the
/// light gives a surface facing it, times cos); returns pixels checked.
fn check_floor_direct(light: &Light, albedo: f32) -> usize {
    let gpu = gpu();
    let scene = floor_with(*light, albedo, None);
    let out = render(&gpu, &scene, &direct_only(192, 1024), 1).readback;
    let (mut checked, mut worst) = (0, 0f64);
    for (i, (pos, direct)) in out.position.iter().zip(&out.direct).enumerate() {
        if pos[3] <= 0.0 {
            continue;
        }
        let p = dvec(pos);
        let cos = DVec3::Y.dot(light.direction_from(p)).max(0.0);
        let expected = light.irradiance_facing(p) * (albedo as f64 / std::f64::consts::PI) * cos;
        if expected.x <= 0.0 {
            continue;
        }
        let got = dvec(direct);
        let rel = ((got - expected).abs() / expected).max_element();
        assert!(
            rel < 0.01,
            "{:?} light, pixel ({}, {}) at {p:?}: direct {got:?} vs formula {expected:?} (relative error {rel:.4})",
            light.kind,
            i as u32 % out.width,
            i as u32 / out.width
        );
        worst = worst.max(rel);
        checked += 1;
    }
    println!(
        "{:?}: checked {checked} pixels, worst relative error {worst:.2e}",
        light.kind
    );
    checked
}

#[test]
fn point_light_on_a_plane_matches_i_cos_over_d_squared() {
    // Every cube face but +y sees part of the floor: the faces' seams cross it.
    let light = point(Vec3::new(0.3, 1.2, -0.2), 7.0);
    assert!(check_floor_direct(&light, 0.6) > 20000);
}

#[test]
fn directional_light_on_a_plane_matches_e_cos() {
    let light = sun(Vec3::new(0.3, -1.0, 0.2), 2.5);
    assert!(check_floor_direct(&light, 0.6) > 20000);
}

/// The floor point at `p` is dark and the one at `beside` is lit within 1%.
fn check_shadow(light: Light, occluder: Vec3, shadow: Vec3, beside: Vec3) {
    let gpu = gpu();
    let albedo = 0.6;
    let scene = floor_with(light, albedo, Some(occluder));
    let settings = direct_only(192, 512);
    let rendered = render(&gpu, &scene, &settings, 1);
    let out = &rendered.readback;
    for (at, lit) in [(shadow, false), (beside, true)] {
        let (x, y) = project(&rendered.uniforms, 192, 192, at).expect("on screen");
        let i = (y * 192 + x) as usize;
        let p = dvec(&out.position[i]);
        assert!(
            p.y.abs() < 1e-3,
            "pixel ({x}, {y}) sees the floor, not {p:?}"
        );
        let cos = DVec3::Y.dot(light.direction_from(p)).max(0.0);
        let formula = light.irradiance_facing(p).x * albedo as f64 / std::f64::consts::PI * cos;
        let got = out.direct[i][0] as f64;
        if lit {
            assert!(
                ((got - formula) / formula).abs() < 0.01,
                "{:?}: lit point {p:?}: {got} vs {formula}",
                light.kind
            );
        } else {
            assert!(
                got < 0.01 * formula,
                "{:?}: shadowed point {p:?}: {got} (unshadowed {formula})",
                light.kind
            );
        }
    }
}

#[test]
fn point_and_directional_lights_cast_shadows() {
    // Point light: the occluder's centre seen from the light lands at
    // light + 1.2 / 0.7 (centre - light) on the floor.
    let light = point(Vec3::new(0.3, 1.2, -0.2), 7.0);
    let c = Vec3::new(1.0, 0.5, 0.5);
    let t = 1.2 / 0.7;
    let shadow = light.position + (c - light.position) * t;
    check_shadow(light, c, shadow, Vec3::new(-1.5, 0.0, -1.5));
    // Directional, 45 degrees: the shadow is the square shifted by 0.5 along x.
    let light = sun(Vec3::new(1.0, -1.0, 0.0), 2.0);
    check_shadow(
        light,
        c,
        Vec3::new(1.5, 0.0, 0.5),
        Vec3::new(-1.5, 0.0, -1.5),
    );
}

/// A closed box of half-size `half` around the origin, every wall facing in.
fn inward_box(light: Light, albedo: f32) -> Scene {
    let mut s = Scene::empty("box", light, looking_down());
    let m = s.add_material("wall", Vec3::splat(albedo));
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = {
                let mut n = Vec3::ZERO;
                n[axis] = -sign;
                n
            };
            let (u, v) = {
                let mut u = Vec3::ZERO;
                u[(axis + 1) % 3] = 1.0;
                let mut v = Vec3::ZERO;
                v[(axis + 2) % 3] = 1.0;
                (u, v)
            };
            let c = -n;
            let mut corners = [c - u - v, c + u - v, c + u + v, c - u + v];
            if (corners[1] - corners[0])
                .cross(corners[2] - corners[0])
                .dot(n)
                < 0.0
            {
                corners.reverse();
            }
            s.add_quad("wall", corners, m);
        }
    }
    s
}

#[test]
fn point_light_in_a_closed_box_reflects_rho_4_pi_i() {
    let gpu = gpu();
    let (albedo, intensity) = (0.4, 3.0);
    let scene = inward_box(point(Vec3::new(0.2, 0.3, -0.1), intensity), albedo);
    let settings = RenderSettings {
        method: Method::new("multires-gather"),
        ..direct_only(32, 256)
    };
    let mut r = Renderer::new(&gpu, &scene, &settings).unwrap();
    assert_eq!(r.light_views().len(), 6, "a point light is six cube faces");
    let (mut flux, mut solid_angle) = (0.0f64, 0.0f64);
    for f in 0..6 {
        r.set_only_view(Some(f)).unwrap();
        r.render_frames(1, |_| {}).unwrap();
        let rsm = r.readback().unwrap().rsm;
        let face_flux: f64 = rsm.flux.iter().map(|t| t[0] as f64).sum();
        let face_dw: f64 = rsm.flux.iter().map(|t| t[3] as f64).sum();
        // Every texel sees a wall, so every texel carries flux.
        assert!(
            rsm.position.iter().all(|p| p[3] > 0.0),
            "face {f} has empty texels"
        );
        flux += face_flux;
        solid_angle += face_dw;
    }
    drop(r);
    assert_validation_clean(&gpu);
    let four_pi = 4.0 * std::f64::consts::PI;
    let expected = albedo as f64 * four_pi * intensity as f64;
    println!("flux {flux} vs {expected}; solid angle {solid_angle} vs {four_pi}");
    assert!(
        ((flux - expected) / expected).abs() < 0.01,
        "flux {flux} vs rho 4 pi I = {expected}"
    );
    assert!(
        ((solid_angle - four_pi) / four_pi).abs() < 1e-3,
        "the texels' solid angles sum to {solid_angle}, not 4 pi"
    );
}

#[test]
fn directional_light_reflects_rho_e_times_the_lit_area() {
    let gpu = gpu();
    let (albedo, e) = (0.7, 2.0);
    // Straight down, the floor (2 x 2 m) covers the RSM up to its one-texel
    // rim; slanted by theta, the RSM sees the floor's area times cos theta.
    for (direction, cos_theta) in [(-Vec3::Y, 1.0), (Vec3::new(0.0, -1.0, 1.0), 0.5f64.sqrt())] {
        let mut scene = floor_scene(sun(direction, e), looking_down(), 1.0, albedo);
        scene.lights[0].direction = direction.normalize();
        let settings = RenderSettings {
            method: Method::new("multires-gather"),
            ..direct_only(32, 256)
        };
        let mut r = Renderer::new(&gpu, &scene, &settings).unwrap();
        let view = r.light_views()[0];
        r.render_frames(1, |_| {}).unwrap();
        let rsm = r.readback().unwrap().rsm;
        drop(r);
        let texel = 2.0 * view.half_extent as f64 / 256.0;
        let lit = rsm.position.iter().filter(|p| p[3] > 0.0).count() as f64;
        let flux: f64 = rsm.flux.iter().map(|t| t[0] as f64).sum();
        let a_rsm = lit * texel * texel;
        let expected = albedo as f64 * e as f64 * 4.0 * cos_theta;
        println!(
            "{direction}: flux {flux}, rho E A_rsm {}, rho E A cos {expected}",
            albedo as f64 * e as f64 * a_rsm
        );
        assert!(
            ((flux - albedo as f64 * e as f64 * a_rsm) / flux).abs() < 1e-4,
            "flux {flux} vs rho E A_rsm over the {lit} lit texels"
        );
        assert!(
            ((flux - expected) / expected).abs() < 0.01,
            "flux {flux} vs rho E A cos theta = {expected}"
        );
        // No solid angle: parallel rays.
        assert!(rsm.flux.iter().all(|t| t[3] == 0.0));
        // The world areas are the texel areas over cos_j.
        let area: f64 = rsm.position.iter().map(|p| p[3] as f64).sum();
        assert!(
            ((area - 4.0) / 4.0).abs() < 0.01,
            "RSM areas sum to {area}, the floor is 4 m^2"
        );
    }
    assert_validation_clean(&gpu);
}

fn cornell_with(lights: Vec<Light>) -> Scene {
    let mut s = cornell_box();
    s.animation = None;
    s.lights = lights;
    s
}

fn box_point() -> Light {
    point(Vec3::new(0.3, 1.3, 0.2), 2.0)
}

fn box_sun() -> Light {
    // Through the ceiling, which faces down and so is culled from the RSM (as
    // single-sided faces turned away from a light are).
    sun(Vec3::new(0.4, -1.0, -0.3), 1.5)
}

#[test]
fn two_lights_render_as_the_sum_of_each_alone() {
    let gpu = gpu();
    // Every GPU method; the reference in several submissions per light view.
    for method in isr::methods::REGISTRY.iter().map(|d| d.key()) {
        let mut settings = RenderSettings {
            width: 48,
            height: 48,
            rsm_resolution: 32,
            method,
            ..Default::default()
        };
        // Only the parameters the method reads.
        for name in isr::methods::params_of(isr::methods::find(method).unwrap()).map(|p| p.name()) {
            match name {
                "vpls" => VPLS.set(&mut settings, 64),
                "reference-chunk" => reference::CHUNK.set(&mut settings, 48 * 48 * 32 * 8),
                "isr-base" => BASE.set(&mut settings, 16),
                _ => {}
            }
        }
        let read = |lights| render(&gpu, &cornell_with(lights), &settings, 1).readback;
        let both_run = render(
            &gpu,
            &cornell_with(vec![box_point(), box_sun()]),
            &settings,
            1,
        );
        let names: Vec<&str> = both_run.stats.frames[0].iter().map(|p| p.name).collect();
        let passes = |name: &str| names.iter().filter(|n| n.starts_with(name)).count();
        if passes("upsample") > 0 {
            // An upsampling per view (six faces, the sun); one refinement.
            let counts = ["upsample", "geometry-mips", "stencil-refine"].map(passes);
            assert_eq!(counts, [7, 1, 1], "{method:?}: {names:?}");
        }
        let both = both_run.readback;
        let a = read(vec![box_point()]);
        let b = read(vec![box_sun()]);
        let mut worst = 0f64;
        for layer in 0..2 {
            let get = |r: &isr::readback::Readback| {
                if layer == 0 {
                    r.direct.clone()
                } else {
                    r.indirect.clone()
                }
            };
            let (s, x, y) = (get(&both), get(&a), get(&b));
            let total = |v: &[[f32; 4]]| v.iter().map(|t| t[0] as f64).sum::<f64>();
            assert!(
                (layer == 1 && method == Method::new("none"))
                    || (total(&x) > 0.0 && total(&y) > 0.0),
                "each light alone lights the box"
            );
            for i in 0..s.len() {
                let sum = dvec(&x[i]) + dvec(&y[i]);
                let diff = (dvec(&s[i]) - sum).abs().max_element();
                worst = worst.max(diff / sum.max_element().max(1e-3));
            }
        }
        println!("{method:?}: worst relative difference {worst:.2e}");
        assert!(
            worst < 1e-5,
            "{method:?}: two lights differ from the sum of each alone by {worst:.2e}"
        );
    }
}

/// Relative RMSE of the indirect image over pixels with geometry.
fn relative_rmse(a: &isr::readback::Readback, reference: &isr::readback::Readback) -> f64 {
    let (mut err, mut norm) = (0.0, 0.0);
    for (i, p) in reference.position.iter().enumerate() {
        if p[3] > 0.0 {
            err += (dvec(&a.indirect[i]) - dvec(&reference.indirect[i])).length_squared();
            norm += dvec(&reference.indirect[i]).length_squared();
        }
    }
    (err / norm).sqrt()
}

/// HISR against the dense gather of every RSM texel, as tau falls.
fn hisr_converges(light: Light) {
    let gpu = gpu();
    let scene = cornell_with(vec![light]);
    let rsm = 32;
    let base = |method| RenderSettings {
        width: 48,
        height: 48,
        rsm_resolution: rsm,
        method,
        ..Default::default()
    };
    let dense = render(
        &gpu,
        &scene,
        &base(Method::new("multires-gather")).with(&VPLS, rsm * rsm),
        1,
    )
    .readback;
    let mut errors = Vec::new();
    for tau in [0.5, 0.05, 0.002, 0.00001] {
        let s = base(hisr::KEY)
            .with(&hisr::TAU, tau)
            .with(&hisr::MAX_DEPTH, 5); // log2(32): down to single texels
        let out = render(&gpu, &scene, &s, 1).readback;
        errors.push(relative_rmse(&out, &dense));
    }
    println!("{:?}: relative RMSE over tau {errors:?}", light.kind);
    for w in errors.windows(2) {
        assert!(w[1] <= w[0], "the error must fall as tau falls: {errors:?}");
    }
    assert!(
        errors[0] > 0.01,
        "the coarsest tau should be approximate: {errors:?}"
    );
    assert!(
        *errors.last().unwrap() < 1e-4,
        "the finest tau should match the dense gather: {errors:?}"
    );
}

#[test]
fn hisr_converges_for_a_point_light() {
    hisr_converges(box_point());
}

#[test]
fn hisr_converges_for_a_directional_light() {
    hisr_converges(box_sun());
}

#[test]
fn too_many_light_views_are_refused_before_allocating() {
    let gpu = gpu();
    let lights = (0..11)
        .map(|i| point(Vec3::new(0.0, 1.0 + 0.01 * i as f32, 0.0), 1.0))
        .collect();
    let scene = cornell_with(lights);
    let e = match Renderer::new(&gpu, &scene, &direct_only(32, 32)) {
        Ok(_) => panic!("66 RSMs must be refused"),
        Err(e) => format!("{e:#}"),
    };
    assert!(e.contains("11 lights") && e.contains("66 RSMs"), "{e}");
}

#[test]
fn lights_export_load_and_animate_with_their_own_nodes() {
    // The built-in sweep moves light 0; a point light and a sun join it.
    let mut scene = cornell_box();
    scene.lights.push(box_point());
    scene.lights.push(box_sun());
    let json = isr::scene::export::to_gltf_json(&scene).unwrap();
    let dir = std::env::temp_dir().join(format!("isr-lights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("lights.gltf");
    std::fs::write(&path, json).unwrap();
    let loaded = isr::scene::gltf_load::load(&path).unwrap();
    let kinds: Vec<_> = loaded.lights.iter().map(|l| l.kind).collect();
    assert_eq!(
        kinds,
        [LightKind::Spot, LightKind::Point, LightKind::Directional]
    );
    for (a, b) in loaded.lights.iter().zip(&scene.lights) {
        assert!(a.position.abs_diff_eq(b.position, 1e-5), "{a:?} vs {b:?}");
        assert!(a.direction.abs_diff_eq(b.direction, 1e-5), "{a:?} vs {b:?}");
        assert_eq!((a.intensity, a.color), (b.intensity, b.color));
    }
    let rest = loaded.state_at(0.0);
    let later = loaded.state_at(1.0);
    assert!(
        later.lights[0].direction.x > 0.5,
        "the spot sweeps: {:?}",
        later.lights[0]
    );
    assert_eq!(later.lights[1..], rest.lights[1..], "the others stay");
}

#[test]
fn isr_merges_a_flat_floor_under_cube_faces_and_orthographic_rsms() {
    // On one plane every patch is valid (docs/algorithm.md section 2.5), so
    // Basic ISR merges up to the root: one patch per RSM. A step in the floor
    // (a raised square) makes the patches over its edges invalid.
    let gpu = gpu();
    let settings = RenderSettings {
        method: Method::new("isr"),
        ..direct_only(32, 64)
    }
    .with(&BASE, 16);
    for light in [
        point(Vec3::new(0.3, 1.2, -0.2), 7.0),
        sun(Vec3::new(0.3, -1.0, 0.2), 2.0),
    ] {
        for step in [false, true] {
            let mut scene = floor_scene(light, looking_down(), 1.0, 0.5);
            if step {
                let m = scene.add_material("step", Vec3::splat(0.5));
                let h = 0.5;
                scene.add_quad(
                    "step",
                    [
                        Vec3::new(-h, 0.3, h),
                        Vec3::new(h, 0.3, h),
                        Vec3::new(h, 0.3, -h),
                        Vec3::new(-h, 0.3, -h),
                    ],
                    m,
                );
            }
            let mut r = Renderer::new(&gpu, &scene, &settings).unwrap();
            // The point light's -y face sees the whole floor.
            let view = if light.kind == LightKind::Point { 3 } else { 0 };
            if light.kind == LightKind::Point {
                assert_eq!(r.light_views()[view].direction, -Vec3::Y);
            }
            r.set_only_view(Some(view)).unwrap();
            r.render_frames(1, |_| {}).unwrap();
            let chosen = r.isr_chosen().unwrap().unwrap();
            let rsm = r.readback().unwrap().rsm;
            drop(r);
            let flux: f64 = rsm.flux.iter().map(|t| t[0] as f64).sum();
            let chosen_flux: f64 = chosen.iter().map(|p| p.flux[0] as f64).sum();
            assert!(
                ((flux - chosen_flux) / flux).abs() < 1e-4,
                "chosen patches carry the RSM's flux"
            );
            println!("{:?}, step {step}: {} patches", light.kind, chosen.len());
            if step {
                assert!(
                    chosen.len() > 16,
                    "{:?}: the step's edges must stay unmerged: {}",
                    light.kind,
                    chosen.len()
                );
            } else {
                assert_eq!(
                    chosen.len(),
                    1,
                    "{:?}: one plane merges into one patch",
                    light.kind
                );
            }
        }
    }
    assert_validation_clean(&gpu);
}

#[test]
fn a_point_light_is_one_layered_draw_and_six_faces_each_timed_by_name() {
    let gpu = gpu();
    let scene = cornell_with(vec![box_point(), box_sun()]);
    let settings = RenderSettings {
        width: 32,
        height: 32,
        rsm_resolution: 32,
        ..Default::default()
    };
    let stats = render(&gpu, &scene, &settings, 1).stats;
    let names: Vec<&str> = stats.frames[0].iter().map(|p| p.name).collect();
    let count = |n: &str| names.iter().filter(|&&x| x == n).count();
    assert_eq!(count("rsm-cube[0]"), 1, "{names:?}");
    for face in ["+x", "-x", "+y", "-y", "+z", "-z"] {
        assert_eq!(count(&format!("rsm-face[0{face}]")), 1, "{names:?}");
        assert_eq!(count(&format!("gather[0{face}]")), 1, "{names:?}");
    }
    assert_eq!(count("rsm[1]"), 1, "the sun's own RSM: {names:?}");
    assert_eq!(count("gbuffer"), 1, "{names:?}");
    assert_eq!(count("light-sum[1]"), 1, "{names:?}");
    assert!(!names.contains(&"rsm"), "{names:?}");
}
