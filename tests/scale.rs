//! Scenes at any scale and place (issue 29, README "Scale and precision"):
//! a scene moved by whole render-origin cells, or scaled by a power of two,
//! renders bit for bit the same; scaled by any factor from 1e-4 to 1e4 it
//! renders the same within float rounding; an object far away changes
//! nothing; every frame's pose is checked.
mod common;

use common::gltf::{animated_doc, load_in, sampler};
use common::*;
use glam::{Mat4, Vec3};
use isr::readback::Readback;
use isr::scene::{cornell::cornell_box, LightKind, Scene};
use serde_json::json;

/// The Cornell box with positions on a grid of 1/16 m (vertices, light,
/// camera), so that a translation by a multiple of 16 m below 2^20 is exact
/// in f32 and any change in the image is the renderer's own.
fn grid_box(light: isr::scene::Light) -> Scene {
    let mut s = cornell_with(vec![light]);
    let snap = |v: Vec3| (v * 16.0).round() / 16.0;
    for m in &mut s.meshes {
        for v in &mut m.vertices {
            v.position = snap(Vec3::from(v.position)).to_array();
        }
    }
    for l in &mut s.lights {
        l.position = snap(l.position);
    }
    let c = &mut s.camera.world_from_camera;
    c.w_axis = snap(c.w_axis.truncate()).extend(1.0);
    s
}

/// `scene` scaled by `s` about the origin, then moved by `offset`, with what
/// keeps the image the same: spot and point intensities times s^2, ranges
/// and the camera's znear times s.
fn transformed(scene: &Scene, s: f32, offset: Vec3) -> Scene {
    let mut t = scene.clone();
    let world = Mat4::from_translation(offset) * Mat4::from_scale(Vec3::splat(s));
    for i in &mut t.instances {
        i.world_from_object = world * i.world_from_object;
    }
    for l in &mut t.lights {
        l.position = world.transform_point3(l.position);
        if l.kind != LightKind::Directional {
            l.intensity *= s * s;
        }
        l.range = l.range.map(|r| r * s);
    }
    let c = &mut t.camera;
    c.world_from_camera.w_axis = world
        .transform_point3(c.world_from_camera.w_axis.truncate())
        .extend(1.0);
    c.znear *= s;
    t
}

fn lights() -> Vec<isr::scene::Light> {
    let spot = cornell_box().lights[0];
    vec![spot, box_point(), box_sun()]
}

/// The methods checked: direct light only, the paper's two, a baseline.
const METHODS: [&str; 4] = ["none", "multires-gather", "hisr", "rsm-gather"];

fn frame(gpu: &isr::vk::Gpu, scene: &Scene, method: &'static str) -> Readback {
    let s = small_params(sized(method, 48, 48, 64), 64, 16, 1 << 20);
    render(gpu, scene, &s, 1).readback
}

fn assert_bits(what: &str, a: &Readback, b: &Readback) {
    for (layer, x, y) in [
        ("direct", &a.direct, &b.direct),
        ("indirect", &a.indirect, &b.indirect),
    ] {
        let differ = x.iter().zip(y).filter(|(p, q)| p != q).count();
        assert_eq!(differ, 0, "{what}: {differ} pixels of {layer} differ");
    }
    assert!(
        geometry_pixels(a) > a.position.len() / 2,
        "{what}: the box is in view"
    );
}

/// Relative RMSE of direct and indirect over the pixels with geometry in both.
fn rmse(a: &Readback, b: &Readback) -> (f64, f64) {
    let mask: Vec<bool> = a
        .position
        .iter()
        .zip(&b.position)
        .map(|(p, q)| p[3] > 0.0 && q[3] > 0.0)
        .collect();
    (
        relative_rmse(&a.direct, &b.direct, &mask),
        relative_rmse(&a.indirect, &b.indirect, &mask),
    )
}

#[test]
fn a_scene_moved_by_whole_cells_renders_bit_for_bit_the_same() {
    let gpu = gpu();
    for light in lights() {
        let base = grid_box(light);
        // 2^19 m: 16 m above the grid's f32 limit is 2^20.
        let moved = transformed(&base, 1.0, Vec3::splat(524288.0));
        for method in METHODS {
            let what = format!("{method}, {:?} light, moved 524288 m", light.kind);
            assert_bits(
                &what,
                &frame(&gpu, &base, method),
                &frame(&gpu, &moved, method),
            );
        }
    }
}

#[test]
fn a_scene_scaled_by_a_power_of_two_renders_bit_for_bit_the_same() {
    let gpu = gpu();
    for light in lights() {
        let base = grid_box(light);
        for k in [-12, 12] {
            let scaled = transformed(&base, 2f32.powi(k), Vec3::ZERO);
            for method in METHODS {
                let what = format!("{method}, {:?} light, scaled 2^{k}", light.kind);
                assert_bits(
                    &what,
                    &frame(&gpu, &base, method),
                    &frame(&gpu, &scaled, method),
                );
            }
        }
    }
}

/// Any factor: only rounding differs (measured at most 1.4e-5).
#[test]
fn a_scene_scaled_from_1e_minus_4_to_1e4_renders_the_same_within_rounding() {
    let gpu = gpu();
    for light in lights() {
        let base = cornell_with(vec![light]);
        for s in [1e-4f32, 0.1, 30.0, 1e4] {
            let scaled = transformed(&base, s, Vec3::ZERO);
            for method in ["none", "hisr"] {
                let (d, i) = rmse(&frame(&gpu, &scaled, method), &frame(&gpu, &base, method));
                println!(
                    "{method}, {:?} light, scaled {s}: direct {d:.1e}, indirect {i:.1e}",
                    light.kind
                );
                assert!(
                    d < 1e-4 && i < 1e-4,
                    "{method}, {:?} light, scaled {s}: direct {d:.1e}, indirect {i:.1e}",
                    light.kind
                );
            }
        }
    }
}

/// Moved by an amount that is no whole cell, a scene's own positions round
/// (f32); moved 1 km that is 6e-5 m, and the image stays within 1e-4. The
/// rounding moves shadow edges, whose images change by the move over the
/// edge's width: so the shadow map here is the RSM's 64 texels (measured
/// 7.1e-5 spot, 4.5e-5 point, 2.4e-5 sun), as the bound was set; the default
/// 1024 texels are 16 times sharper (spot 1.2e-4 at 1024, 1.6e-4 at 2048),
/// and whole-cell moves at the default size stay bit for bit the same.
#[test]
fn a_scene_moved_1_km_renders_the_same_within_rounding() {
    let gpu = gpu();
    let frame = |scene: &Scene, method: &'static str| {
        let mut s = small_params(sized(method, 48, 48, 64), 64, 16, 1 << 20);
        s.shadow_resolution = s.rsm_resolution;
        render(&gpu, scene, &s, 1).readback
    };
    for light in lights() {
        let base = cornell_with(vec![light]);
        let moved = transformed(&base, 1.0, Vec3::new(1000.3, -700.7, 900.1));
        for method in ["none", "hisr"] {
            let (d, i) = rmse(&frame(&moved, method), &frame(&base, method));
            println!(
                "{method}, {:?} light, moved 1 km: direct {d:.1e}, indirect {i:.1e}",
                light.kind
            );
            assert!(
                d < 1e-4 && i < 1e-4,
                "{method}, {:?}: direct {d:.1e}, indirect {i:.1e}",
                light.kind
            );
        }
    }
}

/// One object far away (a block of the box moved 50 km out) leaves the image
/// as if it were not in the scene: for a spot and a point light exactly, for
/// a directional one, whose RSM is then fitted to the view, within 1e-4.
#[test]
fn a_far_object_changes_nothing() {
    let gpu = gpu();
    for light in lights() {
        let with = cornell_with(vec![light]);
        // The short block of the built-in box.
        let block = 5;
        let mut far = with.clone();
        far.instances[block].world_from_object = Mat4::from_translation(Vec3::new(5e4, 0.0, 0.0))
            * far.instances[block].world_from_object;
        let mut without = with.clone();
        without.instances.remove(block);
        for method in METHODS {
            let (a, b) = (frame(&gpu, &far, method), frame(&gpu, &without, method));
            let what = format!("{method}, {:?} light, a block 50 km away", light.kind);
            if light.kind == LightKind::Directional {
                let (d, i) = rmse(&a, &b);
                assert!(
                    d < 1e-4 && i < 1e-4,
                    "{what}: direct {d:.1e}, indirect {i:.1e}"
                );
            } else {
                assert_bits(&what, &a, &b);
            }
        }
    }
    // The path tracer too: a block 500 km away once made its rays start
    // 9 m off every surface.
    let mut far = cornell_box();
    far.animation = None;
    let block = 5;
    far.instances[block].world_from_object =
        Mat4::from_translation(Vec3::new(5e5, 0.0, 0.0)) * far.instances[block].world_from_object;
    let mut without = far.clone();
    without.instances.remove(block);
    let settings = isr::pathtrace::PathTraceSettings {
        width: 32,
        height: 32,
        spp: 4,
        seed: 1,
        exposure: 1.0,
        bounces: isr::bounces::Bounces::ONE,
    };
    let (a, b) = (
        isr::pathtrace::render(&far, &settings, |_, _| {}),
        isr::pathtrace::render(&without, &settings, |_, _| {}),
    );
    // Pixels whose ray meets an edge of the box exactly hit either face,
    // whichever the BVH (which holds the far block) offers first: equal
    // surfaces elsewhere give equal light, bit for bit.
    let geometry = geometry_pixels(&a);
    assert!(geometry > 512, "the path tracer sees the box");
    let same: Vec<usize> = (0..a.normal.len())
        .filter(|&k| a.position[k][3] > 0.0 && a.normal[k] == b.normal[k])
        .collect();
    assert!(
        (geometry - same.len()) * 100 < geometry,
        "{} pixels met another surface",
        geometry - same.len()
    );
    for k in same {
        assert_eq!(
            (a.direct[k], a.indirect[k]),
            (b.direct[k], b.indirect[k]),
            "pathtrace, a block 500 km away: pixel {k}"
        );
    }
}

/// A camera whose scale animates to 0, a block animated past the coordinate
/// limit and CUBICSPLINE keys that sample to NaN: each is an error naming the
/// time and the channel, where the static case was already refused.
#[test]
fn every_frame_pose_is_checked() {
    let nodes = json!([
        {"mesh": 0, "translation": [0.0, 0.0, -2.0]},
        {"camera": 0, "translation": [0.0, 0.5, 3.0]},
        {"translation": [0.0, 3.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
    ]);
    struct Case {
        name: &'static str,
        node: usize,
        path: &'static str,
        times: Vec<f32>,
        values: Vec<f32>,
        interpolation: &'static str,
        expect: &'static str,
    }
    let cases = [
        Case {
            name: "camera scaled to 0",
            node: 1,
            path: "scale",
            times: vec![0.0, 1.0],
            values: vec![1., 1., 1., 0., 0., 0.],
            interpolation: "LINEAR",
            expect: "the camera has no orientation",
        },
        Case {
            name: "block sent to 1e30 m",
            node: 0,
            path: "translation",
            times: vec![0.0, 1.0],
            values: vec![0., 0., -2., 1e30, 0., 0.],
            interpolation: "LINEAR",
            expect: "reaches 1.000e30 m",
        },
        Case {
            name: "keys at +-3e38 s",
            node: 0,
            path: "translation",
            times: vec![-3e38, 3e38],
            // In-tangent, value, out-tangent per key.
            values: vec![
                0., 0., 0., 0., 0., -2., 0., 0., 0., 0., 0., 0., 0., 0., -2., 0., 0., 0.,
            ],
            interpolation: "CUBICSPLINE",
            expect: "from the origin",
        },
    ];
    for c in cases {
        let Case {
            name,
            node,
            path,
            times,
            values,
            interpolation,
            expect,
        } = c;
        let doc = animated_doc(nodes.clone(), |d| {
            let s = sampler(d, interpolation, &times, &values, "VEC3");
            json!([{"name": name, "samplers": [s], "channels": [
                {"sampler": 0, "target": {"node": node, "path": path}},
            ]}])
        });
        let scene = load_in(&format!("pose-{node}-{path}"), &doc).unwrap();
        let t = if interpolation == "CUBICSPLINE" {
            0.0
        } else {
            1.0
        };
        if interpolation != "CUBICSPLINE" {
            scene
                .pose_at(0.0)
                .unwrap_or_else(|e| panic!("{name} at 0 s: {e:#}"));
        }
        let e = format!("{:#}", scene.pose_at(t).unwrap_err());
        assert!(
            e.contains(&format!("at t = {t} s"))
                && e.contains(expect)
                && e.contains(name)
                && e.contains(path),
            "{name}: {e}"
        );
    }
}

/// Below 1e-6 m across a scene is refused (its areas and squared distances
/// would reach f32's smallest numbers); just above, it loads and renders.
#[test]
fn a_scene_too_small_is_refused_and_one_just_large_enough_renders() {
    use common::gltf::cornell_scaled_without_camera_and_light as scaled;
    let e = format!("{:#}", load_in("scale-tiny", &scaled(1e-7)).unwrap_err());
    assert!(
        e.contains("the scene is too small") && e.contains("at least 1e-6 m across"),
        "{e}"
    );
    let scene = load_in("scale-small", &scaled(1e-6)).unwrap();
    let out = render(&gpu(), &scene, &sized("hisr", 32, 32, 32), 1).readback;
    assert!(geometry_pixels(&out) > 0 && out.indirect.iter().any(|p| p[0] > 0.0));
}

/// The path tracer lights the box scaled to 2e-6 m as it lights it at home:
/// its parallel-ray test was absolute (1e-12 m^2), and refused every
/// triangle of the scaled box (a black image where HISR was lit).
#[test]
fn the_path_tracer_renders_a_box_2e_minus_6_m_across_as_at_home() {
    let mut home = cornell_box();
    home.animation = None;
    let tiny = transformed(&home, 1e-6, Vec3::ZERO);
    let settings = isr::pathtrace::PathTraceSettings {
        width: 24,
        height: 24,
        spp: 4,
        seed: 1,
        exposure: 1.0,
        bounces: isr::bounces::Bounces::ONE,
    };
    let (a, b) = (
        isr::pathtrace::render(&home, &settings, |_, _| {}),
        isr::pathtrace::render(&tiny, &settings, |_, _| {}),
    );
    assert!(geometry_pixels(&b) > 24 * 24 / 2, "the box is in view");
    // Rays through an edge of the box hit either face, whichever rounding
    // favours (6 of 576 pixels here): elsewhere the same surface gives the
    // same light, but for rounding.
    let geometry = geometry_pixels(&a);
    let same: Vec<usize> = (0..a.normal.len())
        .filter(|&k| {
            let n = |x: [f32; 4]| Vec3::new(x[0], x[1], x[2]);
            a.position[k][3] > 0.0
                && n(a.normal[k]).dot(n(b.normal[k])) > 0.999
                && a.albedo[k] == b.albedo[k]
        })
        .collect();
    assert!(
        (geometry - same.len()) * 50 < geometry,
        "{} of {geometry} pixels met another surface",
        geometry - same.len()
    );
    let close = |x: [f32; 4], y: [f32; 4]| {
        (0..3).all(|c| (x[c] - y[c]).abs() <= 1e-3 * x[c].abs().max(1e-3))
    };
    for k in same {
        assert!(
            close(a.direct[k], b.direct[k]) && close(a.indirect[k], b.indirect[k]),
            "pixel {k}: direct {:?} and {:?}, indirect {:?} and {:?}",
            a.direct[k],
            b.direct[k],
            a.indirect[k],
            b.indirect[k]
        );
    }
}

/// The built-in box as a glTF under a root node moved (9e5, -2e5, 3e5) m,
/// its camera and light with it (inside the 1e6 m budget): its transforms
/// composed in f64 and its own origin subtracted before f32, it renders as
/// it does at home, bit for bit (its image was 13% off). A light given in
/// world metres (`--light`, a description) lands where it does at home.
#[test]
fn a_gltf_moved_9e5_m_renders_as_at_home() {
    let home_doc = common::gltf::cornell_json();
    let mut far_doc = home_doc.clone();
    let nodes = far_doc["scenes"][0]["nodes"].clone();
    let root = far_doc["nodes"].as_array().unwrap().len();
    let offset = [9e5, -2e5, 3e5];
    far_doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"children": nodes, "translation": offset}));
    far_doc["scenes"][0]["nodes"] = json!([root]);
    let home = load_in("scale-home", &home_doc).unwrap();
    let far = load_in("scale-far", &far_doc).unwrap();
    assert_eq!(far.origin, glam::DVec3::from(offset));
    let gpu = gpu();
    for method in METHODS {
        let (a, b) = (frame(&gpu, &home, method), frame(&gpu, &far, method));
        assert_bits(&format!("{method}, moved 9e5 m"), &a, &b);
    }
    let light = |scene: &Scene, at: glam::DVec3| {
        let mut s = scene.clone();
        let spec = isr::scene::description::parse_light(&format!(
            "spot:position={},{},{}:target={},{},{}",
            at.x,
            at.y + 1.9,
            at.z,
            at.x,
            at.y,
            at.z - 0.5
        ))
        .unwrap();
        isr::scene::description::apply(&mut s, &[("--light 1".into(), spec)], None).unwrap();
        s.lights[0]
    };
    let (a, b) = (light(&home, glam::DVec3::ZERO), light(&far, far.origin));
    assert_eq!((a.position, a.direction), (b.position, b.direction));
}
