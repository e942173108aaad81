//! Several lights at once and the light views they render as
//! (docs/algorithm.md section 2.4): sums of lights for every method, the
//! passes of cube faces and several views, the limit on views, lights in
//! files, Basic ISR's merges under cube faces and orthographic RSMs. (Direct
//! light per kind: `direct_light.rs`; RSM energy: `rsm.rs`; HISR's
//! convergence: `light_space.rs`.)
mod common;

use common::*;
use glam::Vec3;
use isr::methods::isr::BASE;
use isr::renderer::Renderer;
use isr::scene::{cornell::cornell_box, LightKind};
use isr::settings::{Method, RenderSettings};

fn direct_only(width: u32, rsm: u32) -> RenderSettings {
    sized("none", width, width, rsm)
}

#[test]
fn two_lights_render_as_the_sum_of_each_alone() {
    let gpu = gpu();
    // Every GPU method; the reference in several submissions per light view.
    for method in isr::methods::REGISTRY.iter().map(|d| d.key()) {
        // Only the parameters the method reads.
        let settings = small_params(
            RenderSettings {
                method,
                ..sized("none", 48, 48, 32)
            },
            64,
            16,
            48 * 48 * 32 * 8,
        );
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
                add_square(&mut scene, "step", Vec3::new(0.0, 0.3, 0.0), 0.5, 0.5);
            }
            let mut r = Renderer::new(&gpu, &scene, &settings).unwrap();
            // The point light's -y face sees the whole floor.
            let view = if light.kind == LightKind::Point { 3 } else { 0 };
            if light.kind == LightKind::Point {
                assert_eq!(r.light_views()[view].direction, -Vec3::Y);
            }
            r.set_only_view(Some(view)).unwrap();
            r.render_frames(1, |_| {}).unwrap();
            let chosen = r.light_patches().unwrap().unwrap();
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
