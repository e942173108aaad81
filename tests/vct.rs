//! Method `vct`, voxel cone tracing (docs/algorithm.md section 9): whole
//! frames at small sizes, held to what is known exactly (the closed
//! sphere's uniform first bounce, a lone plane's zero) and to the dense
//! reference (the box's indirect energy); the leak through a wall thinner
//! than a cell, measured and bounded; every light type validation-clean.
mod common;

use common::*;
use glam::{DVec3, Vec3};
use isr::methods::reference::CHUNK;
use isr::methods::vct::{CONES, LOBE};
use isr::readback::Readback;
use isr::scene::{Camera, LightKind, Scene};
use isr::settings::RenderSettings;
use isr::voxel_grid::GRID;

fn vct(size: u32, rsm: u32, grid: u32) -> RenderSettings {
    sized("vct", size, size, rsm).with(&GRID, grid)
}

/// Sum of the first channel of `values` over the pixels `keep` picks.
fn sum_where(r: &Readback, values: &[[f32; 4]], keep: impl Fn(usize) -> bool) -> f64 {
    (0..values.len())
        .filter(|&i| r.position[i][3] > 0.0 && keep(i))
        .map(|i| values[i][0] as f64)
        .sum()
}

/// Inside a closed sphere the first bounce's irradiance is `rho Phi / A`
/// everywhere (shared docs, section 11). VCT's mean over the lit cap and
/// over the unlit wall, each against it.
#[test]
fn inside_a_closed_sphere_the_first_bounce_is_near_uniform() {
    let rho = 0.5;
    let (scene, area) = sphere::sphere(Vec3::splat(rho as f32), 3);
    let gpu = gpu();
    let r = render(&gpu, &scene, &vct(64, 128, 64), 1).readback;
    let expected = rho * sphere::spot_power() / area;
    let mut worst: f64 = 0.0;
    for (group, on_cap) in [("lit cap", true), ("unlit wall", false)] {
        let pick = |i: usize| (r.direct[i][0] > 0.0) == on_cap;
        let n = (0..r.indirect.len())
            .filter(|&i| r.position[i][3] > 0.0 && pick(i))
            .count();
        let mean = sum_where(&r, &r.indirect, pick) / n as f64;
        let off = mean / expected - 1.0;
        println!("{group} ({n} px): E = {mean:.5}, expected {expected:.5}: off by {off:+.3}");
        assert!(n > 300, "{group}: {n} pixels");
        assert!(off.is_finite(), "{group}: {mean}");
        worst = worst.max(off.abs());
    }
    // VCT is low here, and it is the method's error, not noise (integer
    // sums, no sampling): a cone stops at alpha 0.95 and steps half its
    // width, so it crosses the far wall in one or two samples of a level
    // whose cells are a quarter of the sphere, reaching alpha 0.6-0.9
    // before it leaves the grid, and the bright cap reaches the unlit
    // wall blurred into the mean of the whole surface at those levels.
    // Measured at 64^3, 6 cones: -27% on the cap, -38% on the unlit wall.
    // The bound, 45%, holds the method to that (a lost factor of 2, as an
    // averaged mip or a wrong area gives, fails it).
    assert!(worst < 0.45, "off by {worst:.3}");
}

/// A lone lit plane: nothing else reflects, so there is no indirect light,
/// and a cone starting a cell off the plane must not see the plane itself.
/// With the lobe the plane's cells send light only upward, away from the
/// cones' returns: exactly zero. Without it (isotropic cells) the plane
/// lights itself; that figure is printed (docs/experiments.md).
#[test]
fn a_lone_lit_plane_receives_nothing_from_itself() {
    let scene = floor_scene(
        spot(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, 10.0, 40.0, 50.0),
        looking_down(),
        2.0,
        0.5,
    );
    let gpu = gpu();
    let read = |lobe: bool| render(&gpu, &scene, &vct(48, 64, 32).with(&LOBE, lobe), 1).readback;
    let (on, off) = (read(true), read(false));
    let direct = sum_where(&on, &on.direct, |_| true);
    let (a, b) = (
        sum_where(&on, &on.indirect, |_| true),
        sum_where(&off, &off.indirect, |_| true),
    );
    println!(
        "indirect / direct: {:.2e} with the lobe, {:.4} isotropic",
        a / direct,
        b / direct
    );
    assert!(direct > 0.0);
    assert_eq!(a, 0.0, "the plane lights itself: {:.3e}", a / direct);
    // The isotropic cells must show the failure the lobe removes (or the
    // test above proves nothing about the lobe).
    assert!(b > 0.0);
}

/// A lit wall behind a thin wall: a spot on the left lights a floor and a
/// tall wall 0.1 m thick at x = 0 (under a cell at 32^3: 0.14 m); a
/// receiver at x = 0.8 faces the wall, in its shadow. What reaches the
/// receiver with the wall, against what reaches it without (the same
/// light, nothing between): the leak.
fn wall_scene(wall: bool) -> Scene {
    let light = spot(
        Vec3::new(-1.6, 1.9, 0.0),
        Vec3::new(-0.6, 0.0, 0.0),
        20.0,
        30.0,
        40.0,
    );
    let camera = Camera::look_at(
        Vec3::new(0.4, 1.0, 3.0),
        Vec3::new(0.8, 0.9, 0.0),
        Vec3::Y,
        50f32.to_radians(),
        0.05,
    );
    let mut scene = Scene::empty("wall", light, camera);
    let white = scene.add_material("white", Vec3::splat(0.8));
    scene.add_quad("floor", square(Vec3::ZERO, 2.0), white);
    if wall {
        let (v, i) = isr::scene::cuboid(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.1, 2.0, 4.0), 0.0);
        scene.add_mesh("wall", v, i, white);
    }
    let v = Vec3::new;
    scene.add_quad(
        "receiver",
        [
            v(0.8, 0.0, -2.0),
            v(0.8, 0.0, 2.0),
            v(0.8, 2.0, 2.0),
            v(0.8, 2.0, -2.0),
        ],
        white,
    );
    scene
}

#[test]
fn a_wall_thinner_than_a_cell_leaks_a_bounded_share() {
    let gpu = gpu();
    let s = vct(64, 128, 32);
    let behind = |r: &Readback| sum_where(r, &r.indirect, |i| r.position[i][0] > 0.75);
    let with = render(&gpu, &wall_scene(true), &s, 1).readback;
    let without = render(&gpu, &wall_scene(false), &s, 1).readback;
    let pixels = (0..with.position.len())
        .filter(|&i| with.position[i][3] > 0.0 && with.position[i][0] > 0.75)
        .count();
    let (a, b) = (behind(&with), behind(&without));
    println!(
        "receiver ({pixels} px): {a:.3} behind the wall, {b:.3} without it: {:.3} leaks",
        a / b
    );
    assert!(pixels > 500, "the camera sees the receiver");
    assert!(b > 0.0);
    // The wall's cells are opaque (a cell face of surface or more), so a
    // cone crossing the wall at the finest level is stopped; light leaks
    // where a cone is already wider than a cell when it reaches the wall,
    // and a coarse cell averages the wall with the empty cells beside it.
    // Measured at 32^3: 10.6%; the bound allows a fifth.
    assert!(a < 0.2 * b, "the wall leaks {:.3}", a / b);
}

/// In the box without its blocks (a convex room: visibility changes
/// nothing, so the reference needs none) VCT's indirect energy over the
/// image against the dense reference's, which is the one-bounce truth up to
/// its RSM's sampling.
#[test]
fn in_the_box_the_indirect_energy_is_near_the_reference() {
    let scene = cornell_at_rest(false);
    let gpu = gpu();
    let (size, rsm) = (64, 64);
    let reference = render(
        &gpu,
        &scene,
        &sized("reference", size, size, rsm).with(&CHUNK, 1 << 22),
        1,
    )
    .readback;
    let energy = |r: &Readback| -> DVec3 {
        (0..r.indirect.len())
            .filter(|&i| r.position[i][3] > 0.0)
            .map(|i| dvec(&r.indirect[i]))
            .sum()
    };
    let truth = energy(&reference);
    let traced = isr::pathtrace::render(
        &scene,
        &isr::pathtrace::PathTraceSettings {
            width: size,
            height: size,
            spp: 64,
            seed: 1,
            exposure: 1.0,
            bounces: isr::bounces::Bounces::ONE,
        },
        |_, _| {},
    );
    println!(
        "reference / one-bounce path-traced truth = {:.3}",
        truth / energy(&traced)
    );
    for cones in [5, 6, 9] {
        let r = render(&gpu, &scene, &vct(size, rsm, 64).with(&CONES, cones), 1).readback;
        let ratio = energy(&r) / truth;
        for (name, axis, sign) in [
            ("floor", 1, 1.0),
            ("ceiling", 1, -1.0),
            ("left", 0, 1.0),
            ("right", 0, -1.0),
            ("back", 2, 1.0),
        ] {
            let pick =
                |x: &Readback, i: usize| x.position[i][3] > 0.0 && x.normal[i][axis] * sign > 0.9;
            let e = |x: &Readback| {
                (0..x.indirect.len())
                    .filter(|&i| pick(x, i))
                    .map(|i| x.indirect[i][0] as f64)
                    .sum::<f64>()
            };
            println!("  {name}: VCT {:.3} reference {:.3}", e(&r), e(&reference));
        }
        println!("{cones} cones: VCT / reference = {ratio:.3}");
        // The goal: within 1.5x either way, per channel. Measured at 64^3:
        // 0.69 (5 cones), 0.71 (6), 0.82 (9); low on the ceiling (0.42),
        // which sees the lit floor only through coarse levels.
        assert!(
            ratio.cmpgt(DVec3::splat(1.0 / 1.5)).all() && ratio.cmplt(DVec3::splat(1.5)).all(),
            "{cones} cones: {ratio}"
        );
    }
}

/// Integer sums: two runs give the same image.
#[test]
fn frames_are_deterministic() {
    let gpu = gpu();
    let s = vct(32, 64, 32);
    let scene = cornell_at_rest(true);
    let a = render(&gpu, &scene, &s, 1).readback;
    let b = render(&gpu, &scene, &s, 1).readback;
    assert_eq!(a.indirect, b.indirect);
}

fn every_light_type_renders_clean(kind: LightKind) {
    let light = match kind {
        LightKind::Spot => isr::scene::cornell::cornell_box().lights[0],
        LightKind::Point => box_point(),
        LightKind::Directional => box_sun(),
    };
    let gpu = validating_gpu();
    for lobe in [true, false] {
        let s = vct(48, 32, 32).with(&LOBE, lobe);
        // `render` fails on any validation message.
        let r = render(&gpu, &cornell_with(vec![light]), &s, 3);
        let names: Vec<&str> = r.stats.frames[0].iter().map(|p| p.name).collect();
        let views = if kind == LightKind::Point { 6 } else { 1 };
        for pass in ["vct-inject", "vct-mips", "vct-trace"] {
            assert_eq!(
                names.iter().filter(|n| n.starts_with(pass)).count(),
                views,
                "{names:?}"
            );
        }
        assert_eq!(
            names.iter().filter(|n| **n == "voxel-surface").count(),
            1,
            "{names:?}"
        );
        let lit = r.readback.indirect.iter().filter(|e| e[0] > 0.0).count();
        assert!(
            lit > geometry_pixels(&r.readback) / 2,
            "{kind:?}: {lit} lit pixels"
        );
    }
}

light_kind_tests!(every_light_type_renders_clean: spot_is_validation_clean, point_is_validation_clean, directional_is_validation_clean);
