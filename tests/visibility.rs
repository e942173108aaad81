//! Indirect visibility (issue 25, `isr::visibility`): the exact limit, one
//! ray per receiver and VPL. Analytic cases (a disc's shadow, a wall, a
//! half-plane), the CPU gather against the GPU's `reference`, no false
//! shadows in an empty convex room, and the dense reference with exact
//! visibility against the path-traced truth. The real-time approximation,
//! `--visibility voxels`, is tested in `voxel_visibility.rs`.
mod common;

use common::*;
use glam::Vec3;
use isr::bench::truth::{trace, ShadowMaps};
use isr::exact_visibility::{gather, patch_irradiance, Vpl};
use isr::pathtrace::Occluders;
use isr::readback::{Readback, RsmReadback};
use isr::scene::cornell::cornell_box;
use isr::scene::{Camera, Scene};

/// Receivers on the floor y = 0, facing up: an n x n grid over [-s, s]^2.
fn floor_receivers(n: u32, s: f32) -> Readback {
    let count = (n * n) as usize;
    let mut position = vec![[0.0; 4]; count];
    for (k, p) in position.iter_mut().enumerate() {
        let (x, z) = ((k as u32 % n) as f32, (k as u32 / n) as f32);
        let at = |i: f32| -s + 2.0 * s * (i + 0.5) / n as f32;
        *p = [at(x), 0.0, at(z), 1.0];
    }
    let zero = vec![[0.0; 4]; count];
    Readback {
        width: n,
        height: n,
        final_radiance: zero.clone(),
        direct: zero.clone(),
        indirect: zero.clone(),
        bounces: vec![],
        albedo: zero,
        normal: vec![[0.0, 1.0, 0.0, 0.0]; count],
        position,
        display: vec![],
        rsm: RsmReadback {
            resolution: 0,
            position: vec![],
            normal: vec![],
            flux: vec![],
        },
    }
}

/// A scene of occluders only (double-sided, so either face blocks).
fn occluders(add: impl FnOnce(&mut Scene, usize)) -> Scene {
    let camera = Camera::look_at(Vec3::new(0.0, 5.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 0.01);
    let mut s = Scene::empty("occluders", sun(-Vec3::Y, 1.0), camera);
    let m = s.add_material("grey", Vec3::splat(0.5));
    s.materials[m].double_sided = true;
    add(&mut s, m);
    s
}

#[test]
fn a_disc_shadows_exactly_the_receivers_its_silhouette_covers() {
    // VPL 2 m up, a disc of radius 0.25 at 1 m: the umbra on the floor is
    // the disc scaled by 2 about the VPL, radius 0.5.
    let scene = occluders(|s, m| disc(s, m, 1.0, 0.25));
    let o = Occluders::new(&scene);
    let g = floor_receivers(40, 1.0);
    let vpl = down(Vec3::new(0.0, 2.0, 0.0), 1.0);
    let e = gather(&g, &[vpl], Some(&o), |_, _| {});
    let (mut inside, mut outside) = (0, 0);
    for (k, p) in g.position.iter().enumerate() {
        let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
        let free = patch_irradiance(Vec3::from_slice(&p[..3]), Vec3::Y, &vpl).x;
        // Away from the umbra's edge by a receiver spacing.
        if r < 0.45 {
            assert_eq!(e[k][0], 0.0, "receiver at r = {r} under the disc is lit");
            inside += 1;
        } else if r > 0.55 {
            assert_eq!(
                e[k][0], free,
                "receiver at r = {r} outside the umbra is shadowed"
            );
            outside += 1;
        }
    }
    // About pi 0.45^2 / 0.05^2 = 254 receivers inside, 1,200 outside.
    assert!(inside > 200 && outside > 1000, "{inside} {outside}");
}

#[test]
fn a_wall_between_a_vpl_and_its_receivers_leaves_them_nothing() {
    // The VPL lights the floor at x > 0 through a wall in the plane x = 0
    // that rises from the floor to 3 m; receivers on the far side (x < 0)
    // get nothing, those on its side all of it.
    let scene = occluders(|s, m| {
        s.add_quad(
            "wall",
            [
                Vec3::new(0.0, 0.0, -2.0),
                Vec3::new(0.0, 0.0, 2.0),
                Vec3::new(0.0, 3.0, 2.0),
                Vec3::new(0.0, 3.0, -2.0),
            ],
            m,
        )
    });
    let o = Occluders::new(&scene);
    let g = floor_receivers(32, 1.0);
    let vpl = down(Vec3::new(0.5, 1.0, 0.0), 1.0);
    let e = gather(&g, &[vpl], Some(&o), |_, _| {});
    let none = gather(&g, &[vpl], None, |_, _| {});
    for (k, p) in g.position.iter().enumerate() {
        if p[0] < 0.0 {
            assert!(none[k][0] > 0.0);
            assert_eq!(e[k][0], 0.0, "behind the wall at x = {}", p[0]);
        } else {
            assert_eq!(e[k][0], none[k][0], "in front of the wall at x = {}", p[0]);
        }
    }
}

#[test]
fn a_half_plane_on_the_axis_takes_about_half() {
    // A square light of 41 x 41 VPLs, 1 m up; a half-plane at 0.5 m covering
    // x < 0: the receiver under the centre sees the half at x > 0.
    let scene = occluders(|s, m| {
        s.add_quad(
            "half-plane",
            [
                Vec3::new(-5.0, 0.5, -5.0),
                Vec3::new(0.0, 0.5, -5.0),
                Vec3::new(0.0, 0.5, 5.0),
                Vec3::new(-5.0, 0.5, 5.0),
            ],
            m,
        )
    });
    let o = Occluders::new(&scene);
    let n = 41;
    let vpls: Vec<Vpl> = (0..n * n)
        .map(|k| {
            let at = |i: i32| 0.3 * (i - n / 2) as f32 / (n / 2) as f32;
            down(Vec3::new(at(k % n), 1.0, at(k / n)), 1.0)
        })
        .collect();
    let g = floor_receivers(1, 1e-3);
    let seen = gather(&g, &vpls, Some(&o), |_, _| {})[0][0];
    let all = gather(&g, &vpls, None, |_, _| {})[0][0];
    let share = seen / all;
    println!("the half-plane leaves {share:.4}");
    // The VPLs at x = 0 are exactly on the edge: half of the light, within
    // that column's share (1/41).
    assert!((share - 0.5).abs() < 0.5 / n as f32 + 1e-3, "{share}");
}

/// The G-buffer, RSM and light views of one reference frame of `scene`.
fn reference_frame(scene: &Scene, n: u32, rsm: u32) -> Rendered {
    render(&gpu(), scene, &sized("reference", n, n, rsm), 1)
}

#[test]
fn the_cpu_gather_is_the_gpu_reference_and_finds_no_shadow_in_an_empty_room() {
    // The box without its blocks is convex: every surface sees every other.
    let mut empty = cornell_box();
    empty.animation = None;
    let keep: Vec<bool> = empty
        .meshes
        .iter()
        .map(|m| !m.name.ends_with("block"))
        .collect();
    empty.instances.retain(|i| keep[i.mesh]);
    let r = reference_frame(&empty, 48, 32);
    let vpls = isr::exact_visibility::texel_vpls(&r.readback.rsm);
    let cpu = gather(&r.readback, &vpls, None, |_, _| {});
    let mask = geometry_mask(&r.readback.position);
    let e = relative_rmse(&cpu, &r.readback.indirect, &mask);
    println!(
        "{} VPLs: the CPU gather is {e:.2e} from the GPU's",
        vpls.len()
    );
    assert!(vpls.len() > 500);
    assert!(e < 1e-4, "CPU gather {e} from the GPU reference");
    let o = Occluders::new(&empty);
    let exact = gather(&r.readback, &vpls, Some(&o), |_, _| {});
    let false_shadows = relative_rmse(&exact, &cpu, &mask);
    println!("exact visibility changes the empty room by {false_shadows:.2e}");
    assert!(false_shadows < 0.005, "{false_shadows}");
}

#[test]
fn exact_visibility_brings_the_dense_reference_to_the_truth_in_the_box_with_blocks() {
    let mut scene = cornell_box();
    scene.animation = None;
    let settings = sized("reference", 64, 64, 64);
    let r = render(&gpu(), &scene, &settings, 1);
    let vpls = isr::exact_visibility::texel_vpls(&r.readback.rsm);
    let o = Occluders::new(&scene);
    let exact = gather(&r.readback, &vpls, Some(&o), |_, _| {});
    let shadows = ShadowMaps::new(
        &r.light_views,
        r.origin,
        settings.shadow_size(),
        settings.pcf_radius,
    );
    let t = trace(
        &scene,
        &r.readback,
        &shadows,
        0.03,
        1,
        isr::bounces::Bounces::ONE,
        |_, _| {},
    );
    let model = |x: &[[f32; 4]]| model_error(x, &t);
    let (with, without) = (model(&exact), model(&r.readback.indirect));
    println!(
        "against the truth ({} spp, noise {:.4}, noise taken out): {without:.4} without visibility, {with:.4} with exact visibility",
        t.spp, t.noise
    );
    assert!(without > 0.08, "{without}");
    assert!(
        with < 0.5 * without && with < 0.06,
        "{with} against {without}"
    );
}

#[test]
fn isr_render_takes_visibility_exact_for_the_reference_and_says_where_it_does_not_apply() {
    let dir = temp_dir("visibility-cli");
    let exr = |name: &str| dir.join(name).to_str().unwrap().to_string();
    common::cli::Isr::tiny(&dir)
        .args(["--method", "reference", "--visibility", "exact", "--out"])
        .arg(exr("exact.exr"))
        .succeeds();
    common::cli::Isr::tiny(&dir)
        .args(["--method", "reference", "--out"])
        .arg(exr("none.exr"))
        .succeeds();
    let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
    // The box's blocks shadow part of its indirect light: the images differ.
    assert_ne!(read("exact.exr"), read("none.exr"));
    // Exact is the reference's CPU limit; the real-time methods say so.
    let err = common::cli::Isr::tiny(&dir)
        .args(["--method", "hisr", "--visibility", "exact"])
        .fails();
    assert!(err.contains("--method reference only"), "{err}");
    common::cli::Isr::tiny(&dir)
        .args(["--method", "hisr", "--visibility", "voxels", "--out"])
        .arg(exr("voxels.exr"))
        .succeeds();
    // A method without the patch formula does not read it.
    let ran = common::cli::Isr::tiny(&dir)
        .args(["--method", "lpv", "--visibility", "voxels"])
        .succeeds();
    assert!(ran.stderr.contains("--visibility"), "{}", ran.stderr);
    let err = common::cli::Isr::tiny(&dir)
        .args([
            "--method",
            "reference",
            "--visibility",
            "exact",
            "--sequence",
        ])
        .arg(exr("seq"))
        .fails();
    assert!(err.contains("drop --sequence"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
