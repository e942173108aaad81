//! The reflective shadow map's radiometry for each kind of light and its
//! quadtree (docs/algorithm.md sections 2 and 2.4): a spot's RSM reflects
//! `rho` times its intensity integrated over the cone, a point light's
//! `rho 4 pi I` in a closed box, a directional light's `rho E` times the lit
//! area; texel solid angles and areas sum to the frustum's and the
//! surface's.
mod common;

use common::*;
use glam::Vec3;
use isr::renderer::Renderer;
use isr::scene::{Camera, Light, Scene};
use std::f64::consts::PI;

/// rho * integral of I(w) over the cone (KHR_lights_punctual's falloff), by
/// Simpson's rule in the polar angle.
fn expected_flux(light: &Light, rho: f64) -> f64 {
    let n = 20_000;
    let b = light.outer_cone as f64;
    let h = b / n as f64;
    let f = |t: f64| light.intensity as f64 * khr_cone_attenuation(light, t.cos()) * t.sin();
    let mut sum = f(0.0) + f(b);
    for k in 1..n {
        sum += f(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    rho * 2.0 * PI * sum * h / 3.0
}

#[test]
fn rsm_flux_sums_to_albedo_times_intensity_over_the_cone() {
    let gpu = gpu();
    let height = 1.0;
    let outer: f32 = 45.0;
    let light = spot(Vec3::new(0.0, height, 0.0), Vec3::ZERO, 7.0, 30.0, outer);
    let camera = Camera::look_at(
        Vec3::new(0.0, 3.0, 3.0),
        Vec3::ZERO,
        Vec3::Y,
        60f32.to_radians(),
        0.1,
    );
    let rho = 0.7;
    // The floor reaches past the RSM frustum on every side: every texel sees it.
    let scene = floor_scene(light, camera, 3.0, rho);
    let settings = sized("none", 64, 64, 256);
    let rsm = render(&gpu, &scene, &settings, 1).readback.rsm;
    // Every texel saw the floor (its solid angle is written wherever geometry
    // was rasterized); exactly the texels the cone lights are non-empty patches.
    assert!(
        rsm.flux.iter().all(|f| f[3] > 0.0),
        "some RSM texels saw no geometry"
    );
    for (n, f) in rsm.normal.iter().zip(&rsm.flux) {
        assert_eq!(
            n[3] == 1.0,
            f[0] > 0.0,
            "lit texels and only they are patches"
        );
    }

    let flux: f64 = rsm.flux.iter().map(|f| f[0] as f64).sum();
    let expected = expected_flux(&light, rho as f64);
    let rel = (flux - expected).abs() / expected;
    println!("RSM flux {flux:.6} W, expected {expected:.6} W (relative error {rel:.2e})");
    assert!(
        rel < 0.01,
        "RSM flux {flux} W vs rho * I * cone solid angle {expected} W"
    );

    // Solid angles: the texels tile the square frustum, 4 asin(sin^2 a).
    let a = (outer as f64).to_radians();
    let omega: f64 = rsm.flux.iter().map(|f| f[3] as f64).sum();
    let omega_expected = 4.0 * (a.sin() * a.sin()).asin();
    assert!(
        (omega - omega_expected).abs() < 0.01 * omega_expected,
        "sum of dw {omega} vs {omega_expected}"
    );

    // Areas: the lit texels tile the floor's disc under the cone, pi (h tan a)^2.
    let area: f64 = rsm.position.iter().map(|p| p[3] as f64).sum();
    let area_expected = std::f64::consts::PI * (height as f64 * a.tan()).powi(2);
    assert!(
        (area - area_expected).abs() < 0.01 * area_expected,
        "sum of A_j {area} vs {area_expected}"
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
    let settings = sized("multires-gather", 32, 32, 256);
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
        let settings = sized("multires-gather", 32, 32, 256);
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

/// One node of the RSM quadtree, reduced on the CPU in f64.
#[derive(Clone, Copy)]
struct Node {
    position: glam::DVec3,
    area: f64,
    normal: glam::DVec3,
    /// 0 empty, 1 valid, -1 invalid (`PATCH_*`); with `borderline` when a
    /// threshold test was within rounding of its limit.
    state: f32,
    borderline: bool,
    flux: glam::DVec4,
}

/// docs/algorithm.md section 2 ("A patch P"), computed independently of the
/// GPU from the RSM itself: flux, solid angle and area add up, position is
/// the mean weighted by the flux's luminance (by area where the patch has
/// no flux), normal the area-weighted mean, and a patch is valid when its non-empty
/// children are valid and lie on one surface (offset from the patch's plane
/// under `depth` times the child's distance to the light, normal within
/// `cos_normal`).
fn cpu_level(
    children: &[Node],
    side: usize,
    light: glam::DVec3,
    depth: f64,
    cos_normal: f64,
) -> Vec<Node> {
    let half = side / 2;
    let mut out = Vec::with_capacity(half * half);
    for y in 0..half {
        for x in 0..half {
            let c: Vec<Node> = (0..4)
                .map(|i| children[(2 * y + (i >> 1)) * side + 2 * x + (i & 1)])
                .collect();
            let area: f64 = c.iter().map(|n| n.area).sum();
            let flux = c.iter().map(|n| n.flux).sum();
            let luminance = |n: &Node| 0.2126 * n.flux.x + 0.7152 * n.flux.y + 0.0722 * n.flux.z;
            let lit: f64 = c.iter().map(luminance).sum();
            let position = if lit > 0.0 {
                c.iter()
                    .map(|n| n.position * luminance(n))
                    .sum::<glam::DVec3>()
                    / lit
            } else if area > 0.0 {
                c.iter().map(|n| n.position * n.area).sum::<glam::DVec3>() / area
            } else {
                glam::DVec3::ZERO
            };
            let normal = c
                .iter()
                .map(|n| n.normal * n.area)
                .sum::<glam::DVec3>()
                .normalize_or_zero();
            let mut borderline = c.iter().any(|n| n.borderline);
            let mut state = 0.0;
            if area > 0.0 {
                let mut one = c.iter().all(|n| n.state != -1.0);
                for n in c.iter().filter(|n| n.state != 0.0) {
                    let offset = (n.position - position).dot(normal).abs();
                    let reach = depth * n.position.distance(light);
                    let cos = n.normal.dot(normal);
                    borderline |= (offset - reach).abs() < 1e-4 * reach.max(1e-6)
                        || (cos - cos_normal).abs() < 1e-4;
                    one &= offset < reach && cos > cos_normal;
                }
                state = if one { 1.0 } else { -1.0 };
            }
            out.push(Node {
                position,
                area,
                normal,
                state,
                borderline,
                flux,
            });
        }
    }
    out
}

#[test]
fn rsm_quadtree_matches_an_independent_cpu_reduction() {
    let gpu = gpu();
    let scene = isr::scene::cornell::cornell_box();
    let settings = sized("multires-gather", 64, 64, 64).with(&isr::regular_vpls::VPLS, 16);
    let m = render_multires(&gpu, &scene, &settings).multires;
    use isr::passes::rsm_tree::{VALIDITY_DEPTH, VALIDITY_NORMAL};
    let light = scene.lights[0].position.as_dvec3();
    let cos_normal = (VALIDITY_NORMAL.get(&settings) as f64).to_radians().cos();
    let v = |a: &[f32; 4]| glam::DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let [pos, nrm, flux] = &m.rsm_tree[0];
    let mut level: Vec<Node> = (0..pos.len())
        .map(|i| Node {
            position: v(&pos[i]),
            area: pos[i][3] as f64,
            normal: v(&nrm[i]),
            state: nrm[i][3],
            borderline: false,
            flux: glam::Vec4::from(flux[i]).as_dvec4(),
        })
        .collect();
    let mut side = settings.rsm_resolution as usize;
    let mut compared = 0;
    let mut invalid = 0;
    for k in 1..m.rsm_tree.len() {
        level = cpu_level(
            &level,
            side,
            light,
            VALIDITY_DEPTH.get(&settings) as f64,
            cos_normal,
        );
        side /= 2;
        let [gpos, gnrm, gflux] = &m.rsm_tree[k];
        for (i, cpu) in level.iter().enumerate() {
            let total = cpu.flux.max_element().max(1e-12);
            let gf = glam::Vec4::from(gflux[i]).as_dvec4();
            assert!(
                (gf - cpu.flux).abs().max_element() <= 1e-4 * total,
                "level {k} texel {i}: flux {gf:?} vs CPU {:?}",
                cpu.flux
            );
            assert!(
                (gpos[i][3] as f64 - cpu.area).abs() <= 1e-4 * cpu.area.max(1e-12),
                "level {k} texel {i}: area"
            );
            if cpu.area > 0.0 {
                assert!(
                    v(&gpos[i]).distance(cpu.position) < 1e-4,
                    "level {k} texel {i}: position {:?} vs CPU {:?}",
                    v(&gpos[i]),
                    cpu.position
                );
                assert!(
                    v(&gnrm[i]).distance(cpu.normal) < 1e-3,
                    "level {k} texel {i}: normal"
                );
            }
            if !cpu.borderline {
                assert_eq!(gnrm[i][3], cpu.state, "level {k} texel {i}: patch state");
                compared += 1;
                invalid += (cpu.state == -1.0) as usize;
            }
        }
    }
    // The box has edges: both outcomes of the validity test were compared.
    assert!(
        compared > 1000 && invalid > 10,
        "{compared} states compared, {invalid} invalid"
    );
}
