//! The CPU path-traced one-bounce reference (docs/algorithm.md sections 1 and 5).
mod common;

use common::*;
use glam::{Vec3, Vec3A};
use isr::bench::truth::{truth_mask, ShadowMaps};
use isr::pathtrace::{render as trace, PathTraceSettings};
use isr::scene::{cornell::cornell_box, cuboid, Camera, Scene};
use isr::settings::{Method, RenderSettings};

fn pt(scene: &Scene, width: u32, height: u32, spp: u32, seed: u64) -> isr::readback::Readback {
    trace(
        scene,
        &PathTraceSettings {
            width,
            height,
            spp,
            seed,
            exposure: 1.0,
            bounces: isr::bounces::Bounces::ONE,
        },
        |_, _| {},
    )
}

#[test]
fn direct_layer_matches_the_rasterised_direct_layer() {
    compare_direct_layers(&cornell_box());
}

#[test]
fn direct_layers_match_for_a_point_and_a_directional_light_together() {
    // The directional light comes through the ceiling, which faces away
    // from it: neither renderer lets a face turned away from a light cast a
    // shadow.
    let scene = cornell_with(vec![box_point(), box_sun()]);
    compare_direct_layers(&scene);
}

/// The path tracer's direct layer against the rasterizer's (RSM 1024), on
/// the pixels the bench compares with the truth (`truth_mask`: away from
/// geometric edges, and from exact shadow edges by PCF's footprint).
fn compare_direct_layers(scene: &Scene) {
    let gpu = gpu();
    let scene = scene.clone();
    let (w, h) = (128, 128);
    let settings = sized("none", w, h, 1024);
    let rendered = render(&gpu, &scene, &settings, 1);
    let raster = &rendered.readback;
    let traced = pt(&scene, w, h, 1, 1);
    let shadows = ShadowMaps::new(
        &rendered.light_views,
        rendered.origin,
        settings.shadow_size(),
        settings.pcf_radius,
    );
    let mask = truth_mask(raster, &traced.direct, &shadows);
    let (mut compared, mut close, mut sum_rel) = (0, 0, 0.0);
    for i in (0..(w * h) as usize).filter(|&i| mask.mask[i]) {
        let (a, b) = (dvec(&traced.direct[i]), dvec(&raster.direct[i]));
        if b.max_element() < 1e-3 {
            continue;
        }
        let rel = ((a - b).abs().max_element()) / b.max_element();
        compared += 1;
        close += (rel < 0.01) as u32;
        sum_rel += rel.min(1.0);
    }
    let mean = sum_rel / compared as f64;
    let e = relative_rmse(&raster.direct, &traced.direct, &mask.mask);
    println!(
        "{compared} lit pixels ({:.1}% of the image left out): {close} within 1%, \
         mean relative difference {mean:.4}, relative RMSE {e:.4}",
        100.0 * mask.left_out()
    );
    assert!(compared > 5000);
    assert!(
        close as f64 > 0.99 * compared as f64,
        "{close} of {compared} within 1%"
    );
    assert!(mean < 0.005, "mean relative difference {mean}");
    assert!(e < 0.005, "relative RMSE {e}");
}

/// Root-mean-square difference of two images' indirect layers over pixels
/// with geometry.
fn rms_difference(a: &isr::readback::Readback, b: &isr::readback::Readback) -> f64 {
    let (mut e, mut n) = (0.0, 0);
    for i in 0..a.indirect.len() {
        if a.position[i][3] > 0.0 {
            e += (dvec(&a.indirect[i]) - dvec(&b.indirect[i])).length_squared();
            n += 1;
        }
    }
    (e / n as f64).sqrt()
}

#[test]
fn indirect_converges_like_one_over_sqrt_spp() {
    let scene = cornell_box();
    // Against a fixed scale (the mean indirect at the highest count): the
    // noise of two seeds' difference must halve with 4x the samples.
    let images: Vec<_> = [16, 64, 256]
        .iter()
        .map(|&spp| (pt(&scene, 48, 48, spp, 1), pt(&scene, 48, 48, spp, 2)))
        .collect();
    let scale = images[2]
        .0
        .indirect
        .iter()
        .map(|p| p[0] as f64)
        .sum::<f64>()
        / images[2].0.indirect.len() as f64;
    let errors: Vec<f64> = images
        .iter()
        .map(|(a, b)| rms_difference(a, b) / scale)
        .collect();
    println!(
        "RMS difference between two seeds at 16, 64, 256 spp, relative to the mean: {errors:?}"
    );
    for w in errors.windows(2) {
        let ratio = w[0] / w[1];
        assert!(
            (1.7..2.3).contains(&ratio),
            "4x the samples should halve the noise: {errors:?}"
        );
    }
}

const SLAB_CENTER: Vec3 = Vec3::new(0.0, 0.6, -0.75);
const SLAB_SIZE: Vec3 = Vec3::new(1.6, 0.06, 0.5);

/// A lit wall, a floor, and a slab between the wall's lit part and the floor
/// under it. The VPL reference ignores that the slab blocks the bounce; the
/// path tracer does not.
fn occluder_scene() -> Scene {
    let light = spot(
        Vec3::new(0.0, 1.6, 2.5),
        Vec3::new(0.0, 1.8, -1.0),
        50.0,
        8.0,
        10.0,
    );
    let camera = Camera::look_at(
        Vec3::new(0.0, 2.2, 2.6),
        Vec3::new(0.0, 0.0, -0.2),
        Vec3::Y,
        60f32.to_radians(),
        0.05,
    );
    let mut s = Scene::empty("occluder", light, camera);
    let white = s.add_material("white", Vec3::splat(0.7));
    let v = Vec3::new;
    s.add_quad(
        "floor",
        [
            v(-2., 0., 3.),
            v(2., 0., 3.),
            v(2., 0., -1.),
            v(-2., 0., -1.),
        ],
        white,
    );
    s.add_quad(
        "wall",
        [
            v(-2., 0., -1.),
            v(2., 0., -1.),
            v(2., 3., -1.),
            v(-2., 3., -1.),
        ],
        white,
    );
    // A closed slab at 0.6 m, from the wall to 0.5 m in front of it.
    let (sv, si) = cuboid(SLAB_CENTER, SLAB_SIZE, 0.0);
    s.add_mesh("slab", sv, si, white);
    s
}

#[test]
fn path_tracer_differs_from_the_vpl_reference_where_the_bounce_is_occluded() {
    let gpu = gpu();
    let scene = occluder_scene();
    let (w, h) = (64, 64);
    let traced = pt(&scene, w, h, 256, 7);
    let reference = render(&gpu, &scene, &sized("reference", w, h, 64), 1).readback;
    // Classify floor pixels by whether the slab blocks their view of the lit
    // wall: segments to a grid of points on the lit part of the wall.
    let (slab_vertices, slab_indices) = cuboid(SLAB_CENTER, SLAB_SIZE, 0.0);
    let blocker = isr::pathtrace::bvh::Bvh::new(
        slab_indices
            .chunks_exact(3)
            .map(|t| isr::pathtrace::bvh::Triangle {
                p: std::array::from_fn(|k| {
                    Vec3A::from(Vec3::from(slab_vertices[t[k] as usize].position))
                }),
                n: [Vec3A::Y; 3],
                uv: [[0.0; 2]; 3],
                material: 0,
                double_sided: true,
            })
            .collect(),
    );
    // The lit part of the wall: the cone (10 degrees at 3.5 m) around (0, 1.8).
    let lit_wall: Vec<Vec3A> = (0..7)
        .flat_map(|i| {
            (0..7).map(move |j| Vec3A::new(-0.45 + 0.15 * i as f32, 1.35 + 0.15 * j as f32, -1.0))
        })
        .collect();
    let (mut occluded, mut open) = ((0.0, 0.0, 0), (0.0, 0.0, 0));
    for i in 0..(w * h) as usize {
        let p = reference.position[i];
        if p[3] <= 0.0 || p[1].abs() > 1e-3 {
            continue; // floor pixels only
        }
        let x = Vec3A::new(p[0], p[1], p[2]);
        let blocked = lit_wall
            .iter()
            .filter(|q| {
                let d = **q - x;
                blocker
                    .intersect(
                        x,
                        d.normalize(),
                        1e-4,
                        d.length(),
                        true,
                        isr::pathtrace::bvh::Cull::BackFaces,
                    )
                    .is_some()
            })
            .count();
        let (t, r) = (
            traced.indirect[i][0] as f64,
            reference.indirect[i][0] as f64,
        );
        if blocked == lit_wall.len() {
            occluded = (occluded.0 + t, occluded.1 + r, occluded.2 + 1);
        } else if blocked == 0 && p[2] > 0.3 {
            open = (open.0 + t, open.1 + r, open.2 + 1);
        }
    }
    println!("occluded floor: {} px, path traced {:.4} vs VPL reference {:.4}; open floor: {} px, {:.4} vs {:.4}",
        occluded.2, occluded.0 / occluded.2 as f64, occluded.1 / occluded.2 as f64,
        open.2, open.0 / open.2 as f64, open.1 / open.2 as f64);
    assert!(
        occluded.2 > 20 && open.2 > 100,
        "regions too small: {} occluded, {} open",
        occluded.2,
        open.2
    );
    assert!(
        occluded.1 > 2.0 * occluded.0,
        "the reference should overestimate the occluded floor"
    );
    let open_rel = (open.0 - open.1).abs() / open.1;
    assert!(
        open_rel < 0.1,
        "on the open floor the two should agree: {open_rel}"
    );
}

/// Open single-sided occluders shadow as the shadow map does: a quad facing
/// the light casts a shadow, one facing away from it (culled in the RSM) does
/// not, in both renderers.
#[test]
fn single_sided_occluders_shadow_alike_in_both_renderers() {
    let gpu = gpu();
    for (facing_light, shadowed) in [(true, true), (false, false)] {
        let scene = spot_over_an_occluder(facing_light);
        let light = scene.lights[0];
        let raster = render(
            &gpu,
            &scene,
            &RenderSettings {
                width: 64,
                height: 64,
                method: Method::new("none"),
                ..Default::default()
            },
            1,
        );
        let traced = pt(&scene, 64, 64, 1, 1);
        let (x, y) = project(&raster, Vec3::ZERO).unwrap();
        let i = (y * 64 + x) as usize;
        let unshadowed = light.intensity as f64 * 0.5 / std::f64::consts::PI / 4.0;
        for (name, direct) in [
            ("raster", raster.readback.direct[i][0]),
            ("path traced", traced.direct[i][0]),
        ] {
            let dark = (direct as f64) < 0.01 * unshadowed;
            assert_eq!(
                dark, shadowed,
                "{name}: quad facing the light {facing_light}: direct {direct}"
            );
        }
    }
}
