//! The multiresolution illumination buffer and `multires-gather`
//! (docs/algorithm.md section 3).
mod common;

use common::*;
use glam::Vec3;
use isr::multires::{Upsample, DEPTH_THRESHOLD, NORMAL_THRESHOLD, STENCIL, UPSAMPLE};
use isr::regular_vpls::RegularVpls;
use isr::regular_vpls::{VplSampling, VPLS, VPL_SAMPLING};
use isr::scene::{cornell::cornell_box, Camera, Scene};
use isr::settings::RenderSettings;

/// `multires-gather` with 256 VPLs at `width` x `height`, RSM 256.
fn settings(width: u32, height: u32) -> RenderSettings {
    sized("multires-gather", width, height, 256).with(&VPLS, 256)
}

/// Thresholds of 0: no texel above level 0 is smooth (the tests are strict `<`).
fn level_zero_only(width: u32, height: u32) -> RenderSettings {
    settings(width, height)
        .with(&DEPTH_THRESHOLD, 0.0)
        .with(&NORMAL_THRESHOLD, 0.0)
}

#[test]
fn stencilled_texels_partition_the_pixels_with_geometry() {
    let gpu = gpu();
    let out = render_multires(&gpu, &cornell_box(), &settings(256, 192));
    let m = &out.multires;
    let (w, h) = (m.width, m.height);
    let mut per_level = vec![0u32; m.levels as usize + 1];
    for l in 0..=m.levels {
        for y in 0..h >> l {
            for x in 0..w >> l {
                let s = m.stencil[l as usize][(y * w + x) as usize];
                assert!(s <= 1, "stencil value {s}");
                per_level[l as usize] += s as u32;
                // The gather marked exactly the stencilled texels as patches.
                let alpha = m.illumination[l as usize][(y * w + x) as usize][3];
                assert_eq!(
                    alpha == 1.0,
                    s == 1,
                    "level {l} texel ({x}, {y}): stencil {s}, gather alpha {alpha}"
                );
            }
        }
    }
    let mut covered_geometry = 0;
    for y in 0..h {
        for x in 0..w {
            let covering = (0..=m.levels)
                .filter(|&l| m.stencil[l as usize][((y >> l) * w + (x >> l)) as usize] == 1)
                .count();
            let geometry = out.readback.position[(y * w + x) as usize][3] > 0.0;
            assert_eq!(
                covering, geometry as usize,
                "pixel ({x}, {y}) (geometry: {geometry}) is covered {covering} times"
            );
            covered_geometry += geometry as u32;
        }
    }
    assert!(covered_geometry > w * h / 2);
    assert!(
        per_level[1..].iter().any(|&c| c > 0),
        "no coarse patches at all: {per_level:?}"
    );
    assert_eq!(
        out.stats.patches_per_level.as_deref(),
        Some(per_level.as_slice()),
        "--stats counts"
    );
}

#[test]
fn background_pixels_get_no_patch() {
    let gpu = gpu();
    // Look past the box's edge so part of the image is background.
    let mut scene = cornell_box();
    scene.camera = Camera::look_at(
        Vec3::new(2.5, 1.5, 3.5),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::Y,
        60f32.to_radians(),
        0.05,
    );
    let out = render_multires(&gpu, &scene, &settings(128, 128));
    let levels = isr::debug_view::patch_levels(&out.multires);
    let mut background = 0;
    for (i, l) in levels.iter().enumerate() {
        let geometry = out.readback.position[i][3] > 0.0;
        assert_eq!(l.is_some(), geometry, "pixel {i}");
        background += (!geometry) as u32;
    }
    assert!(
        background > 1000,
        "the view should include background: {background}"
    );
}

#[test]
fn refinement_is_two_to_one_balanced() {
    let gpu = gpu();
    let out = render_multires(&gpu, &cornell_box(), &settings(256, 256));
    let levels = isr::debug_view::patch_levels(&out.multires);
    let w = out.multires.width as usize;
    let mut max_level = 0;
    for (i, l) in levels.iter().enumerate() {
        let Some(l) = *l else { continue };
        max_level = max_level.max(l);
        for j in [i + 1, i + w] {
            if j >= levels.len() || (j == i + 1 && j % w == 0) {
                continue;
            }
            if let Some(n) = levels[j] {
                assert!(
                    l.abs_diff(n) <= 1,
                    "neighbouring pixels {i} and {j} lie in patches of levels {l} and {n}"
                );
            }
        }
    }
    assert!(
        max_level >= 3,
        "expected coarse patches, the coarsest used is {max_level}"
    );
}

/// Two frontal walls at different depths meeting exactly on the centre pixel
/// border, which is also a border of every level's texels. The discontinuity
/// must still force level-0 patches on both sides.
#[test]
fn discontinuity_on_a_texel_border_is_not_missed() {
    let gpu = gpu();
    let light = spot(
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(0.0, 0.0, -3.0),
        10.0,
        50.0,
        60.0,
    );
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        60f32.to_radians(),
        0.1,
    );
    let mut scene = Scene::empty("step", light, camera);
    let m = scene.add_material("white", Vec3::splat(0.7));
    let v = Vec3::new;
    scene.add_quad(
        "near",
        [
            v(-5., -5., -1.),
            v(0., -5., -1.),
            v(0., 5., -1.),
            v(-5., 5., -1.),
        ],
        m,
    );
    scene.add_quad(
        "far",
        [
            v(0., -9., -3.),
            v(9., -9., -3.),
            v(9., 9., -3.),
            v(0., 9., -3.),
        ],
        m,
    );
    let out = render_multires(&gpu, &scene, &settings(128, 128));
    let rb = &out.readback;
    let depth = |x: u32, y: u32| rb.position[(y * 128 + x) as usize][3];
    assert!(
        (depth(63, 64) - 3.0).abs() < 1e-3,
        "pixel 63 sees the near wall: depth {}",
        depth(63, 64)
    );
    assert!(
        (depth(64, 64) - 5.0).abs() < 1e-3,
        "pixel 64 sees the far wall: depth {}",
        depth(64, 64)
    );
    let levels = isr::debug_view::patch_levels(&out.multires);
    for y in 0..128u32 {
        for x in [63u32, 64] {
            assert_eq!(
                levels[(y * 128 + x) as usize],
                Some(0),
                "pixel ({x}, {y}) beside the step"
            );
        }
    }
    // Away from the step both walls are coarse.
    assert!(levels[(64 * 128 + 16) as usize].unwrap() >= 2);
}

#[test]
fn level_zero_gather_equals_the_cpu_sum() {
    let gpu = gpu();
    let s = level_zero_only(128, 96);
    let out = render_multires(&gpu, &cornell_box(), &s);
    let m = &out.multires;
    assert!(
        out.stats.patches_per_level.as_ref().unwrap()[1..]
            .iter()
            .all(|&c| c == 0),
        "only level 0"
    );
    let k = RegularVpls::of(&s).level as usize;
    assert_eq!(m.rsm_tree[k][0].len(), 256, "256 VPLs at level {k}");
    let vpls = vpls_at(m, k);
    let mut checked = 0;
    for i in (0..out.readback.position.len()).step_by(7) {
        let p = out.readback.position[i];
        if p[3] <= 0.0 {
            continue;
        }
        let expected = cpu_gather(&vpls, dvec(&p), dvec(&out.readback.normal[i]).normalize());
        let got = dvec(&out.readback.indirect[i]);
        let err = (got - expected).abs().max_element();
        assert!(
            err <= 1e-4 * expected.max_element() + 1e-7,
            "pixel {i}: GPU {got:?} vs CPU {expected:?}"
        );
        checked += 1;
    }
    assert!(checked > 1000);
    assert_sampled(checked, 7, &out, 0.5);
}

/// A comparison at every `stride`-th pixel that checked `checked` of them
/// compared enough: at least 90% of the pixels with geometry it sampled, and
/// geometry covers at least `coverage` of the image (an empty or black image
/// cannot pass).
fn assert_sampled(checked: usize, stride: usize, out: &RenderedMultires, coverage: f64) {
    let rb = &out.readback;
    let (geometry, all) = (geometry_pixels(rb), rb.position.len());
    println!("compared {checked} pixels of every {stride}; {geometry} of {all} have geometry");
    assert!(
        geometry as f64 >= coverage * all as f64,
        "only {geometry} of {all} pixels have geometry"
    );
    assert!(
        checked as f64 >= 0.9 * geometry as f64 / stride as f64,
        "compared {checked} pixels, of every {stride}th of {geometry} with geometry"
    );
}

#[test]
fn every_patch_holds_the_cpu_sum_at_its_mean_position_and_normal() {
    let gpu = gpu();
    let s = settings(128, 128);
    let out = render_multires(&gpu, &cornell_box(), &s);
    let m = &out.multires;
    let vpls = vpls_at(m, RegularVpls::of(&s).level as usize);
    let w = m.width;
    let mut checked = vec![0; m.levels as usize + 1];
    for (l, count) in checked.iter_mut().enumerate() {
        let lw = w >> l;
        for y in 0..m.height >> l {
            for x in 0..lw {
                if m.stencil[l][(y * w + x) as usize] != 1 {
                    continue;
                }
                let mean = m.geo_mean[l][(y * lw + x) as usize];
                let normal = m.geo_normal[l][(y * lw + x) as usize];
                let expected = cpu_gather(&vpls, dvec(&mean), dvec(&normal));
                let got = dvec(&m.illumination[l][(y * w + x) as usize]);
                let err = (got - expected).abs().max_element();
                assert!(
                    err <= 1e-4 * expected.max_element() + 1e-7,
                    "level {l} patch ({x}, {y}): GPU {got:?} vs CPU {expected:?}"
                );
                *count += 1;
            }
        }
    }
    assert!(
        checked.iter().filter(|&&c| c > 0).count() >= 3,
        "patches checked per level: {checked:?}"
    );
    // The patches partition the pixels with geometry
    // (`stencilled_texels_partition_the_pixels_with_geometry`): the checked
    // ones cover them all.
    let covered: usize = checked.iter().enumerate().map(|(l, c)| c << (2 * l)).sum();
    let geometry = geometry_pixels(&out.readback);
    assert!(
        geometry > 0 && covered >= geometry,
        "the checked patches cover {covered} pixels, {geometry} have geometry"
    );
}

#[test]
fn stencil_off_shades_every_texel_and_gives_the_same_image() {
    let gpu = gpu();
    let scene = cornell_box();
    let on = render_multires(&gpu, &scene, &settings(128, 128));
    let off = render_multires(&gpu, &scene, &settings(128, 128).with(&STENCIL, false));
    let gather = |r: &RenderedMultires| {
        r.stats.frames[0]
            .iter()
            .find(|p| p.name == "gather")
            .unwrap()
            .samples_passed
            .unwrap()
    };
    let patches: u64 = on
        .stats
        .patches_per_level
        .as_ref()
        .unwrap()
        .iter()
        .map(|&c| c as u64)
        .sum();
    assert_eq!(gather(&on), patches, "with the stencil, only patches pass");
    assert_eq!(
        gather(&off),
        off.total_area,
        "without it, every texel of every layer is shaded"
    );
    assert!(
        patches * 4 < off.total_area,
        "patches should be a small fraction: {patches} of {}",
        off.total_area
    );
    assert_eq!(
        on.readback.indirect, off.readback.indirect,
        "the same sums, masked afterwards"
    );
}

/// A camera facing a flat wall (z = -1) that a lit wall behind the camera
/// (z = 3, facing it) lights indirectly: the whole view is one smooth surface
/// with smoothly varying irradiance, covered by coarse patches.
fn flat_wall_scene() -> Scene {
    let light = spot(
        Vec3::new(0.5, 1.0, 1.0),
        Vec3::new(1.5, 2.0, 3.0),
        20.0,
        20.0,
        30.0,
    );
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.5, 2.0),
        Vec3::new(0.0, 1.5, -1.0),
        Vec3::Y,
        50f32.to_radians(),
        0.1,
    );
    let mut s = Scene::empty("wall", light, camera);
    let white = s.add_material("white", Vec3::splat(0.7));
    let v = Vec3::new;
    s.add_quad(
        "wall",
        [
            v(-6., -4., -1.),
            v(6., -4., -1.),
            v(6., 7., -1.),
            v(-6., 7., -1.),
        ],
        white,
    );
    s.add_quad(
        "source",
        [
            v(6., -4., 3.),
            v(-6., -4., 3.),
            v(-6., 7., 3.),
            v(6., 7., 3.),
        ],
        white,
    );
    s
}

#[test]
fn interpolated_upsampling_leaves_no_seams_on_a_flat_wall() {
    let gpu = gpu();
    let scene = flat_wall_scene();
    let (w, h) = (128, 128);
    let reference = render_multires(&gpu, &scene, &level_zero_only(w, h));
    let run = |upsample| render_multires(&gpu, &scene, &settings(w, h).with(&UPSAMPLE, upsample));
    let interpolated = run(Upsample::Interpolated);
    let nearest = run(Upsample::Nearest);
    let counts = interpolated.stats.patches_per_level.clone().unwrap();
    assert!(
        counts[0] < counts.iter().sum::<u32>() / 4,
        "the wall should be mostly coarse: {counts:?}"
    );
    let worst = |r: &RenderedMultires| {
        let mut worst: f64 = 0.0;
        let mut compared = 0;
        for (i, p) in reference.readback.position.iter().enumerate() {
            if p[3] <= 0.0 {
                continue;
            }
            let (a, b) = (
                dvec(&r.readback.indirect[i]),
                dvec(&reference.readback.indirect[i]),
            );
            worst = worst.max(((a - b).abs() / b).max_element());
            compared += 1;
        }
        // The wall fills the view: every pixel is compared.
        assert_sampled(compared, 1, r, 1.0);
        worst
    };
    let (wi, wn) = (worst(&interpolated), worst(&nearest));

    println!("largest relative difference to the full-resolution gather: interpolated {wi:.4}, nearest {wn:.4}");
    assert!(
        wi < 0.01,
        "interpolated upsampling differs by {wi} from the full-resolution gather"
    );
    assert!(
        wn > 0.01,
        "nearest upsampling should show blocks, but differs by only {wn}"
    );
}

#[test]
fn point_sampled_vpls_scale_flux_by_the_patch_size() {
    let gpu = gpu();
    let s = level_zero_only(64, 64).with(&VPL_SAMPLING, VplSampling::Point);
    let out = render_multires(&gpu, &cornell_box(), &s);
    let m = &out.multires;
    let k = RegularVpls::of(&s).level as usize;
    let span = 1usize << k;
    let r = m.rsm_tree[0][0].len().isqrt();
    // Centre texels of each patch, flux and area scaled by span^2.
    let scale = (span * span) as f64;
    let vpls: Vec<_> = (0..256)
        .filter_map(|j| {
            let (x, y) = ((j % 16) * span + span / 2, (j / 16) * span + span / 2);
            let t = y * r + x;
            let [pos, nrm, flux] = &m.rsm_tree[0];
            (pos[t][3] > 0.0).then(|| {
                (
                    dvec(&pos[t]),
                    dvec(&nrm[t]),
                    dvec(&flux[t]) * scale,
                    pos[t][3] as f64 * scale,
                    patch_level(k, nrm[t][3]),
                )
            })
        })
        .collect();
    let mut checked = 0;
    for i in (0..out.readback.position.len()).step_by(5) {
        let p = out.readback.position[i];
        if p[3] <= 0.0 {
            continue;
        }
        let expected = cpu_gather(&vpls, dvec(&p), dvec(&out.readback.normal[i]).normalize());
        let got = dvec(&out.readback.indirect[i]);
        assert!(
            (got - expected).abs().max_element() <= 1e-4 * expected.max_element() + 1e-7,
            "pixel {i}: {got:?} vs {expected:?}"
        );
        checked += 1;
    }
    assert_sampled(checked, 5, &out, 0.5);
}
