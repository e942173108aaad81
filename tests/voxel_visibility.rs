//! Indirect visibility's real-time approximation, `--visibility voxels`
//! (`voxel_grid`): no false shadows in the empty
//! room, a disc's umbra on the GPU, convergence to the exact limit
//! (`visibility.rs`) as the grid refines, the box against the truth, and
//! validation for every gathering method with it on.
mod common;

use common::*;
use glam::Vec3;
use isr::bench::truth::{trace, ShadowMaps};
use isr::exact_visibility::gather;
use isr::pathtrace::Occluders;
use isr::scene::{Camera, Scene};
use isr::settings::RenderSettings;
use isr::voxel_grid::{GRID, SUBCELLS};

/// The gathering methods, each small.
const GATHERS: [&str; 8] = [
    "rsm-gather",
    "rsm-splat",
    "rsm-splat-restricted",
    "multires-splat",
    "multires-gather",
    "isr",
    "hisr",
    "reference",
];

#[test]
fn voxel_visibility_changes_nothing_in_the_empty_box() {
    // Nothing occludes in a convex room: every method's image with the
    // grid is its image without, within 0.5% (issue 25's goal), at the
    // default grid. What is lost lies along the room's edges, where a
    // segment from a receiver in one wall's cells runs along the other
    // wall within a cell of it (docs/algorithm.md section 5, "Voxel
    // visibility"): it narrows as the grid refines.
    // HISR twice: marching from every receiver, and with the tiles' shared
    // visibility (--hisr-shared-visibility on, at its default refinement).
    use isr::methods::hisr::SHARED_VISIBILITY;
    let gpu = gpu();
    let room = cornell_at_rest(false);
    let n = GRID.get(&RenderSettings::default());
    for (method, shared) in [
        ("reference", false),
        ("rsm-gather", false),
        ("multires-gather", false),
        ("hisr", false),
        ("hisr", true),
    ] {
        let mut s = small_params(sized(method, 64, 64, 64), 1024, 64, 1 << 24);
        SHARED_VISIBILITY.set(&mut s, shared);
        let method = if shared { "hisr, shared" } else { method };
        let without = render(&gpu, &room, &s, 1);
        let mask = geometry_mask(&without.readback.position);
        let grids: &[u32] = if method == "reference" {
            &[32, 64, 128]
        } else {
            &[n]
        };
        let mut errors = vec![];
        for &g in grids {
            let with = render(&gpu, &room, &voxels(s.clone(), g), 1);
            let e = relative_rmse(&with.readback.indirect, &without.readback.indirect, &mask);
            let lossy = (0..mask.len())
                .filter(|&k| {
                    mask[k] && with.readback.indirect[k][0] < 0.99 * without.readback.indirect[k][0]
                })
                .count();
            println!("{method}, grid {g}: the grid changes the empty box by {e:.5} ({lossy} pixels lose over 1%)");
            errors.push((g, e));
        }
        // Away from the room's edges (the truth's mask, section 6.6).
        let shadows = ShadowMaps::new(
            &without.light_views,
            without.origin,
            s.shadow_size(),
            s.pcf_radius,
        );
        let away =
            isr::bench::truth::truth_mask(&without.readback, &without.readback.direct, &shadows)
                .mask;
        let with = render(&gpu, &room, &voxels(s.clone(), n), 1);
        let e = relative_rmse(&with.readback.indirect, &without.readback.indirect, &away);
        println!("{method}, grid {n}, away from edges: {e:.5}");
        assert!(
            e < 0.005,
            "{method}: {e} away from edges; everywhere {errors:?}"
        );
    }
}

/// A floor lit only from a small lit patch of a ceiling 2 m up (a spot
/// 0.5 m under it, aimed up, cone 30 degrees: radius 0.29), with an opaque
/// disc of radius 0.4 at 1 m between them. Lines from a floor point at
/// radius r to the lit patch cross the disc's height at (r +- 0.29) / 2:
/// the umbra is r < 0.51, and beyond r = 1.09 nothing is in the way.
fn disc_between_a_ceiling_and_a_floor() -> Scene {
    let light = spot(
        Vec3::new(0.0, 1.5, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
        20.0,
        25.0,
        30.0,
    );
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.8, 2.6),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::Y,
        60f32.to_radians(),
        0.05,
    );
    let mut s = floor_scene(light, camera, 2.0, 0.5);
    let m = s.add_material("ceiling", Vec3::splat(0.8));
    let mut ceiling = square(Vec3::new(0.0, 2.0, 0.0), 1.0);
    ceiling.reverse(); // facing down
    s.add_quad("ceiling", ceiling, m);
    let d = s.add_material("disc", Vec3::splat(0.5));
    s.materials[d].double_sided = true;
    disc(&mut s, d, 1.0, 0.4);
    s
}

#[test]
fn the_grid_puts_a_discs_umbra_where_the_geometry_does() {
    let gpu = gpu();
    let scene = disc_between_a_ceiling_and_a_floor();
    let s = small_params(sized("reference", 64, 64, 64), 1024, 64, 1 << 24);
    let none = render(&gpu, &scene, &s, 1).readback;
    for method in ["reference", "hisr", "rsm-gather"] {
        let s = small_params(sized(method, 64, 64, 64), 1024, 64, 1 << 24);
        let free = render(&gpu, &scene, &s, 1).readback;
        let with = render(&gpu, &scene, &voxels(s, 64), 1).readback;
        let (mut umbra, mut open) = (0, 0);
        for k in 0..with.position.len() {
            let p = with.position[k];
            // Floor pixels only (the normal faces up, the height is 0).
            if p[3] <= 0.0 || p[1].abs() > 1e-3 || with.normal[k][1] < 0.99 {
                continue;
            }
            let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
            let (e, f) = (with.indirect[k][0], free.indirect[k][0]);
            if r < 0.4 {
                assert!(f > 0.0, "{method}: no light to shadow at r = {r}");
                assert!(
                    e < 0.02 * f,
                    "{method}: r = {r} in the umbra keeps {e} of {f}"
                );
                umbra += 1;
            } else if r > 1.4 {
                assert!(
                    (e - f).abs() <= 1e-3 * f,
                    "{method}: r = {r} in the open has {e} for {f}"
                );
                open += 1;
            }
        }
        println!("{method}: {umbra} floor pixels in the umbra, {open} in the open");
        assert!(umbra > 50 && open > 100, "{method}: {umbra} {open}");
    }
    // The reference's floor under the disc is lit without visibility.
    assert!(none.indirect.iter().any(|e| e[0] > 0.0));
}

#[test]
fn the_grid_converges_to_exact_visibility_and_brings_the_box_nearer_the_truth() {
    // The box with blocks, the dense reference: its error against the exact
    // limit (the CPU's rays) falls as the grid refines, and against the
    // path-traced truth it is well below the error without visibility.
    let gpu = gpu();
    let scene = cornell_at_rest(true);
    let settings = sized("reference", 64, 64, 64);
    let r = render(&gpu, &scene, &settings, 1);
    let vpls = isr::exact_visibility::texel_vpls(&r.readback.rsm);
    let o = Occluders::new(&scene);
    let exact = gather(&r.readback, &vpls, Some(&o), |_, _| {});
    let mask = geometry_mask(&r.readback.position);
    let none = relative_rmse(&r.readback.indirect, &exact, &mask);
    let mut errors = vec![];
    let mut images = vec![];
    for n in [16, 32, 64, 128] {
        let with = render(&gpu, &scene, &voxels(settings.clone(), n), 1).readback;
        let e = relative_rmse(&with.indirect, &exact, &mask);
        println!("grid {n}: {e:.4} from exact visibility (none: {none:.4})");
        errors.push(e);
        images.push((n, with.indirect));
    }
    for w in errors.windows(2) {
        assert!(
            w[1] < w[0],
            "the error does not fall as the grid refines: {errors:?}"
        );
    }
    assert!(errors[3] < 0.25 * none, "{errors:?} against {none}");
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
    let without = model(&r.readback.indirect);
    println!(
        "against the truth ({} spp, noise {:.4}, noise taken out): {without:.4} without visibility, {:.4} exact",
        t.spp,
        t.noise,
        model(&exact)
    );
    for (n, image) in &images {
        println!("  grid {n}: {:.4}", model(image));
    }
    let default = &images[2].1;
    assert!(
        model(default) < 0.5 * without,
        "{} against {without}",
        model(default)
    );
}

#[test]
fn every_gathering_method_takes_the_grid_and_validation_stays_clean() {
    let gpu = validating_gpu();
    let scene = cornell_at_rest(true);
    for method in GATHERS {
        let s = small_params(sized(method, 32, 32, 32), 64, 16, 1 << 20);
        let without = render(&gpu, &scene, &s, 1).readback;
        let with = render(&gpu, &scene, &voxels(s, 32), 2).readback;
        let mask = geometry_mask(&with.position);
        let changed = relative_rmse(&with.indirect, &without.indirect, &mask);
        let (a, b): (f64, f64) = with
            .indirect
            .iter()
            .zip(&without.indirect)
            .map(|(x, y)| (x[0] as f64, y[0] as f64))
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
        println!(
            "{method}: the blocks' shadows change it by {changed:.3}, energy {:.3}",
            a / b
        );
        assert!(with
            .indirect
            .iter()
            .all(|e| e.iter().all(|c| c.is_finite())));
        // The blocks shadow the box's light: less of it arrives.
        assert!(changed > 0.02 && a < b, "{method}: {changed} {a} {b}");
    }
    assert_validation_clean(&gpu);
}

#[test]
fn the_grid_marks_the_boxs_walls_and_leaves_its_inside_empty() {
    // Read the grid back: in the empty box (walls on its bounds), a
    // sub-cell is occupied iff a wall passes through it, and each coarser
    // level is the OR of the finer one.
    let gpu = gpu();
    let room = cornell_at_rest(false);
    let n = 16u32;
    let s = voxels(sized("reference", 16, 16, 16), n);
    let (words, cube, origin) = rendered_grid(&gpu, &room, &s);
    let origin = origin.as_vec3();
    let (lo, hi) = room.bounds().unwrap();
    let corner = Vec3::new(cube[0], cube[1], cube[2]) + origin;
    let cell = cube[3];
    // Whether a quad of the room lies in the plane coordinate `axis` = p
    // (the box is open at the front).
    let wall = |axis: usize, p: f32| {
        room.meshes.iter().any(|m| {
            m.vertices
                .iter()
                .all(|v| (v.position[axis] - p).abs() < 1e-5)
        })
    };
    // Whether the cell [a, b] is crossed by a wall (a quad in one of the
    // box's bound planes; it is open at the front), or lies inside or
    // outside the box away from every wall; a wall on a cell's face may go
    // either way (the test is conservative).
    let judge = |a: Vec3, b: Vec3, size: f32| {
        let eps = 0.01 * size;
        let interior = a.cmpgt(lo + eps).all() && b.cmplt(hi - eps).all();
        let outside = b.cmplt(lo - eps).any() || a.cmpgt(hi + eps).any();
        let overlaps = a.cmplt(hi - eps) & b.cmpgt(lo + eps);
        let crossed = (0..3).any(|axis| {
            let others = (0..3).filter(|&j| j != axis).all(|j| overlaps.test(j));
            let crosses = |p: f32| a[axis] + eps < p && p < b[axis] - eps && wall(axis, p);
            others && (crosses(lo[axis]) || crosses(hi[axis]))
        });
        (crossed, interior || outside)
    };
    // Level 0: each finest cell's mask of its sub-cells (docs/algorithm.md
    // section 5, "Sub-cells"), two words, sub-cell x + 4 (y + 4 z).
    let (m, sub) = (n as usize, SUBCELLS.get(&s) as usize);
    assert_eq!(sub, 4, "the default");
    let (mut wrong, mut walls) = (0, 0);
    let mut previous = vec![false; m * m * m];
    let size = cell / sub as f32;
    for (i, occupied) in previous.iter_mut().enumerate() {
        let mask = words[2 * i] as u64 | (words[2 * i + 1] as u64) << 32;
        *occupied = mask != 0;
        let c = Vec3::new((i % m) as f32, ((i / m) % m) as f32, (i / (m * m)) as f32);
        for q in 0..sub * sub * sub {
            let o = Vec3::new(
                (q % sub) as f32,
                ((q / sub) % sub) as f32,
                (q / (sub * sub)) as f32,
            );
            let a = corner + c * cell + o * size;
            let (crossed, clear) = judge(a, a + size, size);
            let set = mask >> q & 1 == 1;
            walls += crossed as usize;
            wrong += ((crossed && !set) || (clear && set)) as usize;
        }
    }
    println!("sub-cells: {walls} hold a wall, {wrong} wrong");
    assert!(
        walls > 0 && wrong == 0,
        "sub-cells: {wrong} wrong of {walls}"
    );
    // The OR-levels: one bit per cell, each the OR of the 8 cells under it.
    let levels = isr::voxel_grid::levels(n);
    let mut offset = 2 * m * m * m;
    for k in 1..levels {
        let m = (n >> k) as usize;
        let bit = |i: usize| words[offset + i / 32] >> (i % 32) & 1 == 1;
        let occupied: Vec<bool> = (0..m * m * m).map(bit).collect();
        let size = cell * (1 << k) as f32;
        let mut walls = 0;
        for (i, &occupied_i) in occupied.iter().enumerate() {
            let c = Vec3::new((i % m) as f32, ((i / m) % m) as f32, (i / (m * m)) as f32);
            walls += judge(corner + c * size, corner + (c + 1.0) * size, size).0 as usize;
            let child = |dx, dy, dz| {
                let (x, y, z) = (
                    2 * (i % m) + dx,
                    2 * ((i / m) % m) + dy,
                    2 * (i / (m * m)) + dz,
                );
                previous[(z * 2 * m + y) * 2 * m + x]
            };
            let any = (0..8).any(|j| child(j & 1, (j >> 1) & 1, j >> 2));
            assert_eq!(occupied_i, any, "level {k} cell {i}");
        }
        let count = occupied.iter().filter(|&&o| o).count();
        println!(
            "level {k}: {count} of {} cells occupied, {walls} hold a wall",
            m * m * m
        );
        offset += m * m * m / 32;
        previous = occupied;
    }
    assert_eq!(offset * 4, isr::voxel_grid::grid_bytes(n, 4) as usize);
}

#[test]
fn a_method_switch_uses_the_grid_made_with_the_run_and_refuses_one_never_made() {
    // The viewer switches methods within a run: the grid is made with the
    // run whenever --visibility voxels is set, and used by the methods
    // that read it.
    let gpu = gpu();
    let scene = cornell_at_rest(true);
    let hisr = voxels(sized("hisr", 32, 32, 32), 32);
    let mut r =
        isr::renderer::Renderer::new(&gpu, &scene, &voxels(sized("none", 32, 32, 32), 32)).unwrap();
    assert!(r.voxel_grid().is_none(), "direct light alone reads no grid");
    r.render_frames(1, |_| {}).unwrap();
    r.set_method_settings(&hisr).unwrap();
    assert!(r.voxel_grid().is_some());
    r.render_frames(1, |_| {}).unwrap();
    let switched = r.readback().unwrap();
    drop(r);
    let fresh = render(&gpu, &scene, &hisr, 1).readback;
    let mask = geometry_mask(&fresh.position);
    let e = relative_rmse(&switched.indirect, &fresh.indirect, &mask);
    assert!(e < 1e-6, "{e}");
    let without = render(&gpu, &scene, &sized("hisr", 32, 32, 32), 1).readback;
    assert!(relative_rmse(&without.indirect, &fresh.indirect, &mask) > 0.02);
    // A run made without the grid cannot switch to it.
    let mut plain = isr::renderer::Renderer::new(&gpu, &scene, &sized("hisr", 32, 32, 32)).unwrap();
    let err = plain.set_method_settings(&hisr).unwrap_err().to_string();
    assert!(err.contains("start isr with them"), "{err}");
    drop(plain);
    assert_validation_clean(&gpu);
}

#[test]
fn light_does_not_leak_through_a_wall_thinner_than_a_cell() {
    // A wall of no thickness at x = 0 from the floor to the ceiling, a lit
    // patch of the ceiling at x in [0.21, 0.79] (a spot under it aimed up):
    // the floor at x < 0 sees the patch only through the wall, so with the
    // grid it gets nothing; at x > 0.3 nothing is in the way.
    let light = spot(
        Vec3::new(0.5, 1.5, 0.0),
        Vec3::new(0.5, 2.0, 0.0),
        20.0,
        25.0,
        30.0,
    );
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.0, 3.0),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::Y,
        60f32.to_radians(),
        0.05,
    );
    let mut scene = floor_scene(light, camera, 2.0, 0.5);
    let m = scene.add_material("ceiling", Vec3::splat(0.8));
    let mut ceiling = square(Vec3::new(0.0, 2.0, 0.0), 2.0);
    ceiling.reverse();
    scene.add_quad("ceiling", ceiling, m);
    let w = scene.add_material("wall", Vec3::splat(0.5));
    scene.materials[w].double_sided = true;
    scene.add_quad(
        "wall",
        [
            Vec3::new(0.0, 0.0, -2.0),
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(0.0, 2.0, 2.0),
            Vec3::new(0.0, 2.0, -2.0),
        ],
        w,
    );
    let gpu = gpu();
    // The camera sees the wall edge-on, the floor on both sides of it next
    // to each other: HISR's coarse eye-space patches and their upsampling
    // blend across it (section 3), so its pixels are judged from 0.25 m on.
    for (method, margin) in [("reference", 0.02), ("hisr", 0.25)] {
        let s = small_params(sized(method, 64, 64, 64), 1024, 64, 1 << 24);
        let free = render(&gpu, &scene, &s, 1).readback;
        let with = render(&gpu, &scene, &voxels(s, 64), 1).readback;
        let (mut behind, mut open) = (0, 0);
        for k in 0..with.position.len() {
            let p = with.position[k];
            if p[3] <= 0.0 || p[1].abs() > 1e-3 || with.normal[k][1] < 0.99 {
                continue;
            }
            let (e, f) = (with.indirect[k][0], free.indirect[k][0]);
            if p[0] < -margin {
                assert!(
                    f > 0.0,
                    "{method}: no light behind the wall to block at x = {}",
                    p[0]
                );
                assert!(
                    e <= 1e-3 * f,
                    "{method}: {e} of {f} leaks through at x = {}",
                    p[0]
                );
                behind += 1;
            } else if p[0] > 0.3 + margin {
                assert!(
                    (e - f).abs() <= 1e-3 * f,
                    "{method}: x = {}: {e} for {f}",
                    p[0]
                );
                open += 1;
            }
        }
        println!("{method}: {behind} floor pixels behind the wall, {open} in front");
        assert!(behind > 100 && open > 100, "{method}: {behind} {open}");
    }
}

#[test]
fn hisr_shared_tile_visibility_follows_the_per_receiver_march() {
    // `--hisr-shared-visibility on` (pass hisr-visibility): the tile cuts'
    // shared light patches take their visibility from the tile's corners,
    // and where the corners disagree by more than --hisr-shared-refine from
    // the receiver's own march. On the box with blocks it stays near the
    // per-receiver march, nearer with the refinement than without
    // (--hisr-shared-refine 1), and is validation clean.
    use isr::methods::hisr::{SHARED_REFINE, SHARED_VISIBILITY};
    let gpu = validating_gpu();
    let shared = |mut s: RenderSettings, refine: f32| {
        SHARED_VISIBILITY.set(&mut s, true);
        SHARED_REFINE.set(&mut s, refine);
        s
    };
    // 256x256 (16 x 16 tiles): the tiles' corners are 4 cells apart.
    let s = small_params(sized("hisr", 256, 256, 256), 1024, 64, 1 << 24);
    let default_refine = SHARED_REFINE.get(&s);
    let blocks = cornell_at_rest(true);
    let none = render(&gpu, &blocks, &s, 1).readback;
    let march = render(&gpu, &blocks, &per_receiver(voxels(s.clone(), 64)), 1).readback;
    let mask = geometry_mask(&march.position);
    let apart = |refine: f32| {
        let corners = render(&gpu, &blocks, &shared(voxels(s.clone(), 64), refine), 2).readback;
        relative_rmse(&corners.indirect, &march.indirect, &mask)
    };
    let (refined, corners_only) = (apart(default_refine), apart(1.0));
    let grid = relative_rmse(&none.indirect, &march.indirect, &mask);
    println!(
        "box with blocks: shared against the march {refined:.4} (refine {default_refine}), \
         {corners_only:.4} (corners only); the grid's change {grid:.4}"
    );
    assert!(
        corners_only > 0.0 && corners_only < 0.05 && corners_only < grid / 4.0,
        "{corners_only} {grid}"
    );
    assert!(
        refined > 0.0 && refined < corners_only / 2.0 && refined < 0.02,
        "{refined} {corners_only}"
    );
    assert_validation_clean(&gpu);
}

#[test]
fn a_grid_past_the_devices_storage_buffer_range_is_refused_before_allocation() {
    // At 256, with the default 4 sub-cells, the grid takes 130 MiB, more
    // than the 128 MiB lavapipe binds in one storage buffer: the run is
    // refused with the grid that fits, before anything is allocated
    // (validation would report the binding).
    use isr::voxel_grid::grid_bytes;
    let gpu = validating_gpu();
    let range = gpu.limits().max_storage_buffer_range as u64;
    let scene = cornell_at_rest(false);
    let s = voxels(sized("reference", 16, 16, 16), 256);
    if grid_bytes(256, 4) > range {
        let e = isr::renderer::Renderer::new(&gpu, &scene, &s)
            .err()
            .expect("a grid past the range is refused")
            .to_string();
        let fits = (4..=8)
            .map(|k| 1u32 << k)
            .filter(|&n| grid_bytes(n, 4) <= range)
            .max()
            .unwrap();
        assert!(
            e.contains("--visibility-grid 256")
                && e.contains("maxStorageBufferRange")
                && e.contains(&format!("choose --visibility-grid {fits} or less")),
            "{e}"
        );
    } else {
        println!("this device binds {range} bytes at once: the 256 grid fits");
    }
    assert_validation_clean(&gpu);
}
