//! Direct light that does not leak (issue 26, part 5): a court (a floor, two
//! walls meeting at a corner, a turned block) under a low sun from three
//! sides, a spot and a point light, rasterised against the path tracer,
//! whose direct light is noise-free and exactly shadowed. Pixels next to a
//! geometric edge or to an exact shadow edge (one pixel around either) are
//! left out: coverage and PCF's penumbra differ there by construction.
mod common;

use common::*;
use glam::Vec3;
use isr::bench::truth::{truth_mask, ShadowMaps, TruthMask};
use isr::readback::Readback;
use isr::scene::{cuboid, Camera, Light, Scene};

fn court(light: Light) -> Scene {
    let camera = Camera::look_at(
        Vec3::new(2.6, 2.2, 2.8),
        Vec3::new(-0.6, 0.2, -0.6),
        Vec3::Y,
        50f32.to_radians(),
        0.05,
    );
    let mut s = Scene::empty("court", light, camera);
    let grey = s.add_material("grey", Vec3::splat(0.6));
    // Thin walls, seen and lit from both sides.
    s.materials[grey].double_sided = true;
    s.add_quad("floor", square(Vec3::ZERO, 2.0), grey);
    let (h, w) = (0.8, 2.0);
    s.add_quad(
        "wall-x",
        [
            Vec3::new(-w, 0.0, w),
            Vec3::new(-w, 0.0, -w),
            Vec3::new(-w, h, -w),
            Vec3::new(-w, h, w),
        ],
        grey,
    );
    s.add_quad(
        "wall-z",
        [
            Vec3::new(-w, 0.0, -w),
            Vec3::new(w, 0.0, -w),
            Vec3::new(w, h, -w),
            Vec3::new(-w, h, -w),
        ],
        grey,
    );
    let (v, i) = cuboid(Vec3::new(0.3, 0.35, -0.2), Vec3::splat(0.7), 0.4);
    s.add_mesh("block", v, i, grey);
    s
}

/// `scene`'s direct light rasterised at `n` x `n` (RSM 512) and path traced
/// (one sample: direct light is exact and noise-free), and the truth mask
/// they are compared on.
fn rendered_and_traced(
    gpu: &isr::vk::Gpu,
    scene: &Scene,
    n: u32,
) -> (Rendered, Readback, TruthMask) {
    let settings = sized("none", n, n, 512);
    let rendered = render(gpu, scene, &settings, 1);
    let traced = isr::pathtrace::render(
        scene,
        &isr::pathtrace::PathTraceSettings {
            width: n,
            height: n,
            spp: 1,
            seed: 1,
            exposure: 1.0,
            bounces: isr::bounces::Bounces::ONE,
        },
        |_, _| {},
    );
    let shadows = ShadowMaps::new(
        &rendered.light_views,
        rendered.origin,
        settings.rsm_resolution,
        settings.pcf_radius,
    );
    let mask = truth_mask(&rendered.readback, &traced.direct, &shadows);
    (rendered, traced, mask)
}

#[test]
fn direct_light_matches_the_path_tracer_away_from_edges_for_every_light() {
    let gpu = gpu();
    let n = 160;
    let lights = [
        (
            "a low sun behind the walls",
            sun(Vec3::new(1.0, -0.5, 0.6), 3.0),
        ),
        ("a low sun in front", sun(Vec3::new(-1.0, -0.45, 0.35), 3.0)),
        ("a sun grazing a wall", sun(Vec3::new(0.6, -0.3, -1.0), 3.0)),
        (
            "a spot",
            spot(
                Vec3::new(1.9, 1.3, 0.9),
                Vec3::new(-0.5, 0.0, -0.6),
                40.0,
                45.0,
                60.0,
            ),
        ),
        ("a point light", point(Vec3::new(1.3, 0.9, 0.7), 8.0)),
    ];
    for (name, light) in lights {
        let scene = court(light);
        let (rendered, traced, compared) = rendered_and_traced(&gpu, &scene, n);
        let raster = &rendered.readback;
        let mask = &compared.mask;
        let kept = compared.kept();
        let lit = (0..mask.len())
            .filter(|&k| mask[k] && traced.direct[k][0] > 0.0)
            .count();
        let shadowed = (0..mask.len())
            .filter(|&k| mask[k] && traced.direct[k][0] == 0.0)
            .count();
        // Lit where the path tracer has shadow: a leak.
        let leaks = (0..mask.len())
            .filter(|&k| mask[k] && traced.direct[k][0] == 0.0 && raster.direct[k][0] > 0.01)
            .count();
        let e = relative_rmse(&raster.direct, &traced.direct, mask);
        println!("{name}: direct within {e:.4} over {kept} pixels ({lit} lit, {shadowed} shadowed), {leaks} leaking");
        // Both lit and shadowed floor in view, most of the image compared.
        assert!(
            kept * 2 > (n * n) as usize && lit > 2000,
            "{name}: {kept} pixels, {lit} lit"
        );
        assert!(
            e < 0.01,
            "{name}: direct light {e:.4} from the path tracer's"
        );
        assert!(
            leaks * 100 < shadowed,
            "{name}: {leaks} of {shadowed} shadowed pixels lit"
        );
    }
}

/// The Sibenik cathedral (73,564 triangles, 40 m long) lit from the middle of
/// the nave at half its height (issue 26, part 5: a spot there lit about
/// 1,000 shadowed pixels of the galleries and arcades, 19% from the path
/// tracer with 5.6% too much energy). Faces the light grazes (cos < 0.1)
/// are counted apart: within one texel of their own depth slope the shadow
/// test cannot tell an occluder from the face, so a grazing face beside an
/// occluder is lit at its (small) unshadowed value.
#[test]
fn direct_light_in_the_sibenik_cathedral_matches_the_path_tracer_away_from_edges() {
    let gpu = gpu();
    let n = 256;
    let path = isr::scene::description::archive_root().join("sibenik/sibenik.obj");
    let mut scene = isr::scene::load_file(&path, &Default::default())
        .unwrap_or_else(|e| panic!("{e:#}: {}", isr::scene::description::archive_hint()));
    scene.camera = Camera::look_at(
        Vec3::new(-17.0, -8.0, 0.0),
        Vec3::new(8.0, -4.0, 0.0),
        Vec3::Y,
        60f32.to_radians(),
        0.05,
    );
    let hung = Vec3::new(0.0, 0.0, 0.0);
    let lights = [
        (
            "a spot hung in the nave",
            spot(hung, Vec3::new(0.0, -12.0, 0.0), 1500.0, 45.0, 60.0),
        ),
        ("a point light hung in the nave", point(hung, 300.0)),
    ];
    for (name, light) in lights {
        scene.lights = vec![light];
        let (rendered, traced, compared) = rendered_and_traced(&gpu, &scene, n);
        let raster = &rendered.readback;
        let mask = &compared.mask;
        let kept = compared.kept();
        let shadowed = (0..mask.len())
            .filter(|&k| mask[k] && traced.direct[k][0] == 0.0)
            .count();
        let grazed = |k: usize| {
            let p = Vec3::from_slice(&raster.position[k][..3]);
            let normal = Vec3::from_slice(&raster.normal[k][..3]).normalize();
            normal.dot((light.position - p).normalize()) < 0.1
        };
        let leaking: Vec<usize> = (0..mask.len())
            .filter(|&k| mask[k] && traced.direct[k][0] == 0.0 && raster.direct[k][0] > 0.01)
            .collect();
        let grazing = leaking.iter().filter(|&&k| grazed(k)).count();
        let leaks = leaking.len() - grazing;
        let e = relative_rmse(&raster.direct, &traced.direct, mask);
        let energy = |d: &[[f32; 4]]| {
            (0..mask.len())
                .filter(|&k| mask[k])
                .map(|k| d[k][..3].iter().map(|&c| c as f64).sum::<f64>())
                .sum::<f64>()
        };
        let ratio = energy(&raster.direct) / energy(&traced.direct);
        println!(
            "{name}: direct within {e:.4}, energy x{ratio:.4}, over {kept} pixels \
             ({:.0}% left out: {} at geometric edges, {} at shadow edges), \
             {shadowed} shadowed, {leaks} leaking ({grazing} more on grazed faces)",
            100.0 * compared.left_out(),
            compared.geometric_edges,
            compared.shadow_edges
        );
        assert!(
            kept * 10 > (n * n) as usize && shadowed > 2000,
            "{name}: {kept} pixels compared, {shadowed} shadowed"
        );
        assert!(
            e < 0.01,
            "{name}: direct light {e:.4} from the path tracer's"
        );
        assert!((ratio - 1.0).abs() < 0.01, "{name}: energy x{ratio:.4}");
        assert!(
            leaks * 100 < shadowed,
            "{name}: {leaks} of {shadowed} shadowed pixels lit"
        );
    }
}
