//! Light-space hierarchies: Basic ISR and Hierarchical ISR (docs/algorithm.md
//! sections 2 and 4).
mod common;

use common::cli::Isr;
use common::*;
use glam::Vec3;
use isr::gpu_types::PATCH_INVALID;
use isr::methods::hisr::gpu::HISR_INVALID_TAU_SCALE;
use isr::methods::{hisr, isr::BASE};
use isr::passes::rsm_tree::{VALIDITY_DEPTH, VALIDITY_NORMAL};
use isr::regular_vpls::VPLS;
use isr::scene::{cornell::cornell_box, Camera, LightKind};
use isr::settings::{Method, RenderSettings};

fn settings(method: Method, rsm: u32) -> RenderSettings {
    RenderSettings {
        method,
        ..sized("none", 64, 64, rsm)
    }
}

/// HISR against the dense gather of every RSM texel (the converged limit of
/// the light-space choice), as tau falls, for each kind of light and both
/// meanings of tau (`--hisr-tau-mode`): the error
/// falls at every step, more light patches are evaluated per eye-space patch
/// at every step, the coarsest tau is visibly approximate and the finest
/// matches. The spot lights the built-in box; the point and directional
/// lights the still box, with RSMs (six faces for the point light) of 32.
fn hisr_converges(kind: LightKind, mode: hisr::TauMode) {
    let gpu = gpu();
    let (scene, rsm, size, taus): (_, u32, u32, &[f32]) = match kind {
        LightKind::Spot => (
            cornell_box(),
            64,
            64,
            &[0.5, 0.1, 0.02, 0.004, 0.0008, 0.00001],
        ),
        LightKind::Point => (
            cornell_with(vec![box_point()]),
            32,
            48,
            &[0.5, 0.05, 0.002, 0.00001],
        ),
        LightKind::Directional => (
            cornell_with(vec![box_sun()]),
            32,
            48,
            &[0.5, 0.05, 0.002, 0.00001],
        ),
    };
    let at = |method| RenderSettings {
        method,
        ..sized("none", size, size, rsm)
    };
    let dense = render_multires(
        &gpu,
        &scene,
        &at(Method::new("multires-gather")).with(&VPLS, rsm * rsm),
    );
    let mut errors = Vec::new();
    let mut evaluations = Vec::new();
    for &tau in taus {
        let s = at(hisr::KEY)
            .with(&hisr::TAU, tau)
            .with(&hisr::TAU_MODE, mode)
            // log2 of the RSM: down to single texels.
            .with(&hisr::MAX_DEPTH, rsm.ilog2());
        let out = render_multires(&gpu, &scene, &s);
        errors.push(indirect_rmse(&out.readback, &dense.readback));
        evaluations.push(isr::debug_view::light_patch_stats(&out.multires, None).per_patch_mean);
    }
    println!("{kind:?}, {mode:?}: tau {taus:?}: relative RMSE {errors:?}, light patches per eye patch {evaluations:?}");
    for w in errors.windows(2) {
        assert!(
            w[1] <= w[0],
            "{kind:?}: the error must fall as tau falls: {errors:?}"
        );
    }
    for w in evaluations.windows(2) {
        assert!(
            w[1] >= w[0],
            "{kind:?}: smaller tau must evaluate more patches: {evaluations:?}"
        );
    }
    assert!(
        errors[0] > 0.01,
        "{kind:?}: the coarsest setting should be visibly approximate: {errors:?}"
    );
    assert!(
        *errors.last().unwrap() < 1e-4,
        "{kind:?}: the finest setting should match the dense gather: {errors:?}"
    );
}

fn hisr_relative_converges(kind: LightKind) {
    hisr_converges(kind, hisr::TauMode::Relative);
}

fn hisr_absolute_converges(kind: LightKind) {
    hisr_converges(kind, hisr::TauMode::Absolute);
}

light_kind_tests!(hisr_relative_converges:
    hisr_converges_to_the_dense_gather_for_a_spot_light,
    hisr_converges_to_the_dense_gather_for_a_point_light,
    hisr_converges_to_the_dense_gather_for_a_directional_light);

light_kind_tests!(hisr_absolute_converges:
    hisr_with_absolute_tau_converges_for_a_spot_light,
    hisr_with_absolute_tau_converges_for_a_point_light,
    hisr_with_absolute_tau_converges_for_a_directional_light);

#[test]
fn isr_without_merges_equals_regular_sampling_at_its_base_level() {
    let gpu = gpu();
    let scene = cornell_box();
    let base = 16;
    let no_merges = settings(Method::new("isr"), 128)
        .with(&BASE, base)
        .with(&VALIDITY_DEPTH, 0.0)
        .with(&VALIDITY_NORMAL, 0.0);
    let mut r = isr::renderer::Renderer::new(&gpu, &scene, &no_merges).unwrap();
    r.render_frames(1, |_| {}).unwrap();
    let chosen = r.light_patches().unwrap().unwrap();
    let isr_indirect = r.readback().unwrap().indirect;
    drop(r);
    assert_validation_clean(&gpu);
    let regular = render_multires(
        &gpu,
        &scene,
        // The same tree: its validity says how each patch is evaluated
        // (patch_level: a patch spanning a discontinuity at its centre).
        &settings(Method::new("multires-gather"), 128)
            .with(&VPLS, base * base)
            .with(&VALIDITY_DEPTH, 0.0)
            .with(&VALIDITY_NORMAL, 0.0),
    );
    let base_mip = (128u32 / base).ilog2() as f32;
    assert!(
        // normal.w: the level, negated where the patch spans a discontinuity.
        chosen.iter().all(|p| p.normal[3].abs() == base_mip),
        "every chosen patch is a base patch"
    );
    let non_empty = regular.multires.rsm_tree[base_mip as usize][0]
        .iter()
        .filter(|p| p[3] > 0.0)
        .count();
    assert_eq!(
        chosen.len(),
        non_empty,
        "every non-empty base patch is chosen once"
    );
    let lit = regular
        .readback
        .indirect
        .iter()
        .filter(|p| dvec(p).max_element() > 0.0)
        .count();
    assert!(
        2 * lit >= geometry_pixels(&regular.readback),
        "only {lit} pixels have indirect light"
    );
    for (i, (a, b)) in isr_indirect
        .iter()
        .zip(&regular.readback.indirect)
        .enumerate()
    {
        let (a, b) = (dvec(a), dvec(b));
        assert!(
            (a - b).abs().max_element() <= 1e-5 * b.max_element() + 1e-8,
            "pixel {i}: isr {a:?} vs regular {b:?}"
        );
    }
}

#[test]
fn isr_chosen_patches_partition_the_rsm_flux() {
    let gpu = gpu();
    let s = settings(Method::new("isr"), 128).with(&BASE, 32);
    let mut r = isr::renderer::Renderer::new(&gpu, &cornell_box(), &s).unwrap();
    r.render_frames(1, |_| {}).unwrap();
    let chosen = r.light_patches().unwrap().unwrap();
    let rsm = r.readback().unwrap().rsm;
    drop(r);
    assert_validation_clean(&gpu);
    let total: f64 = rsm.flux.iter().map(|f| (f[0] + f[1] + f[2]) as f64).sum();
    let picked: f64 = chosen
        .iter()
        .map(|p| (p.flux[0] + p.flux[1] + p.flux[2]) as f64)
        .sum();
    assert!(
        (picked - total).abs() <= 1e-4 * total,
        "chosen flux {picked} vs RSM flux {total}"
    );
    let area: f64 = rsm.position.iter().map(|p| p[3] as f64).sum();
    let picked_area: f64 = chosen.iter().map(|p| p.position_area[3] as f64).sum();
    assert!(
        (picked_area - area).abs() <= 1e-4 * area,
        "chosen area {picked_area} vs RSM area {area}"
    );
    let base_mip = 2.0; // 128 / 32
    let merged = chosen.iter().filter(|p| p.normal[3] > base_mip).count();
    println!(
        "{} patches chosen, {merged} of them merged above the base",
        chosen.len()
    );
    assert!(
        merged > 0 && chosen.len() < 32 * 32,
        "flat walls should merge into larger patches"
    );
}

/// Every output finite, with the light touching a wall, the camera inside a
/// block, and receivers at zero distance from VPLs (surfaces the RSM sees).
#[test]
fn no_nan_or_inf_in_degenerate_configurations() {
    let gpu = gpu();
    let mut touching = cornell_box();
    touching.lights[0].position = Vec3::new(0.0, 1.0, -1.0); // on the back wall
    touching.lights[0].direction = Vec3::Z;
    let mut inside = cornell_box();
    inside.camera = Camera::look_at(
        Vec3::new(-0.35, 0.6, -0.3),
        Vec3::new(0.0, 0.6, 2.0),
        Vec3::Y,
        60f32.to_radians(),
        0.01,
    );
    let mut grazing = cornell_box();
    grazing.lights[0].position = Vec3::new(0.0, 1e-4, 0.9); // just above the floor
    grazing.lights[0].direction = Vec3::new(0.0, 0.0, -1.0);
    for (name, scene) in [
        ("light on a wall", touching),
        ("camera inside a block", inside),
        ("light on the floor", grazing),
    ] {
        for method in [
            Method::new("none"),
            Method::new("multires-gather"),
            Method::new("isr"),
            Method::new("hisr"),
        ] {
            let s = settings(method, 64);
            let mut r = isr::renderer::Renderer::new(&gpu, &scene, &s).unwrap();
            r.render_frames(1, |_| {}).unwrap();
            let rb = r.readback().unwrap();
            let m = r.readback_multires().unwrap();
            drop(r);
            for (layer, data) in [
                ("final", &rb.final_radiance),
                ("direct", &rb.direct),
                ("indirect", &rb.indirect),
            ] {
                assert!(
                    data.iter().flatten().all(|v| v.is_finite()),
                    "{name}, {}: non-finite values in {layer}",
                    method.name()
                );
            }
            if let Some(m) = m {
                assert!(
                    m.illumination
                        .iter()
                        .flatten()
                        .flatten()
                        .all(|v| v.is_finite()),
                    "{name}, {}: illumination",
                    method.name()
                );
            }
        }
    }
    assert_validation_clean(&gpu);
}

#[test]
fn stats_and_vpl_count_view_from_the_cli() {
    let dir = temp_dir("hisr-cli");
    let ran = Isr::render(&dir)
        .args([
            "--method", "hisr", "--width", "64", "--height", "64", "--rsm", "64",
        ])
        .args(["--frames", "1", "--stats", "--debug-view", "vpl-count"])
        .args(["--png", "h.png", "--out", "h.exr"])
        .succeeds();
    assert!(
        ran.stdout
            .contains("light patches per eye-space patch: min"),
        "{}",
        ran.stdout
    );
    let heat = image::open(dir.join("h-vpl-count.png")).unwrap().to_rgb8();
    let distinct: std::collections::HashSet<_> = heat.pixels().map(|p| p.0).collect();
    assert!(
        distinct.len() > 3,
        "the heat map should vary over the image"
    );
}

/// HISR traverses the quadtree packed into one buffer: node (x, y) of depth d
/// at (4^d - 1) / 3 + y 2^d + x holds exactly the quadtree texel of mip
/// log2 R - d (position and area, normal and state, flux), and in flux.a its
/// squared reach (`hisr_reach`): with relative tau A (1 - tau) / (pi tau), A
/// its area; with absolute tau (the spot light) 4^k T |p - light|^2, k its
/// levels above the finest; invalid patches' reach over
/// HISR_INVALID_TAU_SCALE; -1 at the max depth and for empty nodes. Depths
/// below the max depth are never read, and not packed.
#[test]
fn the_packed_light_tree_is_the_rsm_quadtree_node_for_node() {
    for mode in [hisr::TauMode::Relative, hisr::TauMode::Absolute] {
        packed_tree_matches(mode);
    }
}

fn packed_tree_matches(mode: hisr::TauMode) {
    let gpu = gpu();
    let rsm = 32u32;
    let scene = cornell_box();
    let s = settings(hisr::KEY, rsm)
        .with(&hisr::MAX_DEPTH, 4)
        .with(&hisr::TAU_MODE, mode);
    let mut r = isr::renderer::Renderer::new(&gpu, &scene, &s).unwrap();
    r.render_frames(1, |_| {}).unwrap();
    let packed = r.light_patches().unwrap().expect("hisr packs its tree");
    let m = r.readback_multires().unwrap().unwrap();
    drop(r);
    assert_validation_clean(&gpu);
    let top = rsm.trailing_zeros() as usize;
    let max_depth = hisr::MAX_DEPTH.get(&s) as usize;
    assert!(max_depth < top, "some depths should never split");
    let t = hisr::subdivision_threshold(hisr::TAU.get(&s), rsm) as f64;
    let light = scene.lights[0].position.as_dvec3();
    let side = 1usize << max_depth;
    assert_eq!(packed.len(), (4 * side * side - 1) / 3);
    assert_eq!(packed.len() as u64, isr::methods::hisr::packed_nodes(&s));
    let mut index = 0;
    let (mut lit, mut invalid) = (0, 0);
    for d in 0..=max_depth {
        let side = 1usize << d;
        let [pos, nrm, flux] = &m.rsm_tree[top - d];
        for i in 0..side * side {
            let n = &packed[index + i];
            assert_eq!(n.position_area, pos[i], "depth {d} node {i} position");
            assert_eq!(n.normal, nrm[i], "depth {d} node {i} normal");
            assert_eq!(n.flux[..3], flux[i][..3], "depth {d} node {i} flux");
            let reach = if d >= max_depth || pos[i][3] <= 0.0 {
                -1.0
            } else {
                let p = glam::DVec3::new(pos[i][0] as f64, pos[i][1] as f64, pos[i][2] as f64);
                let scale = if nrm[i][3] == PATCH_INVALID {
                    invalid += 1;
                    1.0 / HISR_INVALID_TAU_SCALE as f64
                } else {
                    1.0
                };
                scale
                    * match mode {
                        hisr::TauMode::Relative => {
                            let tau = hisr::TAU.get(&s) as f64;
                            pos[i][3] as f64 * (1.0 - tau) / (std::f64::consts::PI * tau)
                        }
                        hisr::TauMode::Absolute => {
                            4f64.powi((top - d) as i32) * t * (p - light).length_squared()
                        }
                    }
            };
            let got = n.flux[3] as f64;
            assert!(
                (got - reach).abs() <= 1e-5 * reach.abs(),
                "{mode:?}: depth {d} node {i}: reach {got}, expected {reach}"
            );
            lit += (pos[i][3] > 0.0) as usize;
        }
        index += side * side;
    }
    assert!(lit > 100, "only {lit} nodes saw anything");
    assert!(
        invalid > 0,
        "no invalid node above the max depth was checked"
    );
}

/// HISR's per-tile cuts (`hisr-cut`, docs/algorithm.md section 4.4) change
/// where each fragment's traversal starts, never what it decides: every
/// eye-space patch evaluates exactly the light patches it evaluates when it
/// traverses from the roots, and the images agree to float rounding. Covered:
/// a spot, a point light (six cube faces) with a directional one, partial
/// tiles (80x48 is no multiple of 16), patches coarser than the tile (K = 1),
/// and tiles whose cut overflows (tau so small that every node splits down
/// to the 4096 leaves, more than a tile's entries), with relative and
/// absolute tau.
#[test]
fn hisr_tile_cuts_decide_like_a_traversal_from_the_roots() {
    let gpu = gpu();
    let two_lights = cornell_with(vec![box_point(), box_sun()]);
    use hisr::TauMode::{Absolute, Relative};
    let cases = [
        ("spot", cornell_box(), 0.05, 4, Relative),
        ("spot, coarse patches", cornell_box(), 0.05, 1, Relative),
        ("spot, tiny tau", cornell_box(), 1e-5, 4, Relative),
        ("point + directional", two_lights.clone(), 0.05, 3, Relative),
        ("spot, absolute tau", cornell_box(), 0.05, 4, Absolute),
        ("spot, absolute tiny tau", cornell_box(), 1e-5, 4, Absolute),
        (
            "point + directional, absolute tau",
            two_lights,
            0.05,
            3,
            Absolute,
        ),
    ];
    for (label, scene, tau, tile_level, mode) in cases {
        let with = |k| {
            RenderSettings {
                width: 80,
                height: 48,
                rsm_resolution: 64,
                method: Method::new("hisr"),
                ..Default::default()
            }
            .with(&hisr::TAU, tau)
            .with(&hisr::TAU_MODE, mode)
            .with(&hisr::TILE_LEVEL, k)
            // Levels 0-4: with K = 1 the cut levels' tiles are 2, 4 and 8
            // pixels a side, and level 4's patches are coarser than all.
            .with(&isr::multires::LEVELS, 4)
            // Without the grid: its tile-shared visibility interpolates the
            // tiles' corners, which a walk from the roots does not.
            .with(
                &isr::visibility::VISIBILITY,
                isr::visibility::Visibility::None,
            )
        };
        let tiled = with(tile_level);
        if tau < 1e-3 {
            // Every node splits to max depth 6 for every receiver: 4096
            // leaves in each tile's cut, more than it holds.
            assert!(
                isr::methods::hisr::cut_layout(&tiled).capacity[2] < 4096,
                "{label}"
            );
        }
        let roots = render_multires(&gpu, &scene, &with(0));
        let cut = render_multires(&gpu, &scene, &tiled);
        assert_eq!(
            roots.multires.evaluations, cut.multires.evaluations,
            "{label}: light patches evaluated per eye-space patch"
        );
        let total: u64 = cut
            .multires
            .evaluations
            .iter()
            .flatten()
            .map(|&e| e as u64)
            .sum();
        assert!(total > 0, "{label}: nothing evaluated");
        let peak = roots
            .readback
            .indirect
            .iter()
            .map(|p| dvec(p).max_element())
            .fold(0.0, f64::max);
        assert!(peak > 0.0, "{label}: no indirect light");
        for (i, (a, b)) in roots
            .readback
            .indirect
            .iter()
            .zip(&cut.readback.indirect)
            .enumerate()
        {
            let d = (dvec(a) - dvec(b)).abs().max_element();
            assert!(d <= 1e-5 * peak, "{label}: pixel {i}: {a:?} vs {b:?}");
        }
    }
}

/// With tiles, HISR's sums come in the same order every frame: two runs give
/// the same bits.
#[test]
fn hisr_with_tiles_is_deterministic() {
    let gpu = gpu();
    let s = settings(Method::new("hisr"), 64);
    let a = render_multires(&gpu, &cornell_box(), &s);
    let b = render_multires(&gpu, &cornell_box(), &s);
    assert!(hisr::TILE_LEVEL.get(&s) > 0);
    assert_eq!(a.readback.indirect, b.readback.indirect);
}
