//! glTF loading: the shipped Cornell box file, the node hierarchy, textures,
//! defaults for missing camera and light.
mod common;

use common::gltf::*;
use common::*;
use glam::{Mat4, Vec3};
use isr::scene::{cornell::cornell_box, gltf_load, Scene};
use serde_json::json;

fn world_triangles(s: &Scene) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for inst in &s.instances {
        let m = &s.meshes[inst.mesh];
        for t in m.indices.chunks_exact(3) {
            out.push(std::array::from_fn(|k| {
                inst.world_from_object
                    .transform_point3(Vec3::from(m.vertices[t[k] as usize].position))
            }));
        }
    }
    out
}

#[test]
fn assets_cornell_gltf_is_the_built_in_scene() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell.gltf");
    let file = gltf_load::load(&path).unwrap();
    let builtin = cornell_box();
    assert!(file.warnings.is_empty(), "{:?}", file.warnings);
    let (a, b) = (world_triangles(&file), world_triangles(&builtin));
    assert_eq!(a.len(), b.len());
    // Node traversal order may differ: compare as sets of triangles.
    for t in &b {
        assert!(
            a.iter()
                .any(|u| (0..3).all(|k| u[k].abs_diff_eq(t[k], 1e-6))),
            "triangle {t:?} of the built-in box is missing from assets/cornell.gltf"
        );
    }
    let albedos = |s: &Scene| {
        let mut v: Vec<[u32; 3]> = s
            .materials
            .iter()
            .map(|m| m.base_color.truncate().to_array().map(f32::to_bits))
            .collect();
        v.sort();
        v
    };
    assert_eq!(albedos(&file), albedos(&builtin));
    let (l, m) = (file.lights[0], builtin.lights[0]);
    assert!(l.position.abs_diff_eq(m.position, 1e-6) && l.direction.abs_diff_eq(m.direction, 1e-6));
    assert_eq!(
        (l.intensity, l.inner_cone, l.outer_cone, l.color),
        (m.intensity, m.inner_cone, m.outer_cone, m.color)
    );
    assert!(file
        .camera
        .world_from_camera
        .abs_diff_eq(builtin.camera.world_from_camera, 1e-5));
    assert_eq!(
        (file.camera.yfov, file.camera.znear),
        (builtin.camera.yfov, builtin.camera.znear)
    );
    // The light's sweep: the same animation, and at 0 s the light is at rest.
    assert_eq!(file.animation_duration(), builtin.animation_duration());
    assert!(builtin.animation_duration().is_some());
    let rest = builtin.state_at(0.0).lights[0];
    assert!(
        rest.position.abs_diff_eq(m.position, 1e-6)
            && rest.direction.abs_diff_eq(m.direction, 1e-6)
    );
    for t in [-1.0, 0.0, 0.4, 1.0, 1.7, 2.5, 3.0, 3.9, 4.0, 7.0] {
        let (a, b) = (file.state_at(t), builtin.state_at(t));
        assert_light_and_camera_agree(&a, &b, 1e-6, 1e-5, &format!("at {t} s"));
    }
    assert!(
        builtin.state_at(1.0).lights[0].direction.x > 0.5,
        "the light sweeps"
    );
}

#[test]
fn node_hierarchy_transforms_compose() {
    let mut doc = cornell_json();
    // Put the floor (node 0) under a new parent that lifts it by 0.5 m, and
    // give the floor itself a translation of 0.25 m in x.
    let nodes = doc["nodes"].as_array_mut().unwrap();
    nodes[0] = json!({"mesh": 0, "translation": [0.25, 0.0, 0.0]});
    nodes.push(json!({"children": [0], "translation": [0.0, 0.5, 0.0]}));
    let parent = nodes.len() - 1;
    let scene_nodes = doc["scenes"][0]["nodes"].as_array_mut().unwrap();
    scene_nodes.retain(|n| n != 0);
    scene_nodes.push(json!(parent));
    let scene = load_in("gltf-hierarchy", &doc).unwrap();
    let floor = scene
        .instances
        .iter()
        .find(|i| scene.meshes[i.mesh].name.starts_with("floor"))
        .unwrap();
    assert!(floor
        .world_from_object
        .abs_diff_eq(Mat4::from_translation(Vec3::new(0.25, 0.5, 0.0)), 1e-6));
}

#[test]
fn missing_camera_and_light_get_defaults_with_warnings() {
    let mut doc = cornell_json();
    // The light's animation targets the light node removed below.
    doc.as_object_mut().unwrap().remove("animations");
    let nodes = doc["nodes"].as_array_mut().unwrap();
    nodes.retain(|n| n.get("camera").is_none() && n.get("extensions").is_none());
    let n = nodes.len();
    doc["scenes"][0]["nodes"] = json!((0..n).collect::<Vec<_>>());
    let scene = load_in("gltf-defaults", &doc).unwrap();
    assert_eq!(scene.warnings.len(), 2, "{:?}", scene.warnings);
    assert!(scene
        .warnings
        .iter()
        .any(|w| w.contains("no KHR_lights_punctual light")));
    assert!(scene
        .warnings
        .iter()
        .any(|w| w.contains("no perspective camera")));
    // The default light hangs inside the bounds pointing down.
    assert!(scene.lights[0].direction.abs_diff_eq(-Vec3::Y, 1e-6));
    assert!(scene.lights[0].position.y < 2.0 && scene.lights[0].position.y > 1.5);
}

#[test]
fn base_color_texture_multiplies_the_albedo() {
    let gpu = gpu();
    let dir = temp_dir("gltf-tex");
    // An 8x1 PNG: left half pure red, right half pure blue (sRGB 255 = linear 1),
    // wide enough that bilinear filtering at u = 0.2 and 0.8 sees one color.
    let texels: Vec<u8> = (0..8)
        .flat_map(|x| if x < 4 { [255, 0, 0] } else { [0, 0, 255] })
        .collect();
    std::fs::write(dir.join("tex.png"), png(8, 1, &texels)).unwrap();
    let mut d = Doc::cornell();
    // Material 0 (white, 0.75) on the floor, back wall, ceiling and blocks.
    with_texture(&mut d.json, json!({"uri": "tex.png"}));
    d.json["samplers"] = json!([]);
    // Texture coordinates for the back wall (mesh 2): u from 0 to 1 across it.
    let uv = d.floats(&[0., 1., 1., 1., 1., 0., 0., 0.], "VEC2");
    d.json["meshes"][2]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv);
    let scene = load(&dir, &d.embedded()).unwrap();
    assert_eq!(scene.textures.len(), 1);

    let out = render(&gpu, &scene, &sized("none", 128, 128, 64), 1);
    let rb = &out.readback;
    let albedo_at = |p: Vec3| {
        let (x, y) = project(&out, p).unwrap();
        rb.albedo[(y * rb.width + x) as usize]
    };
    // Back wall at u = 0.2 and u = 0.8.
    let left = albedo_at(Vec3::new(-0.6, 1.8, -1.0));
    let right = albedo_at(Vec3::new(0.6, 1.8, -1.0));
    assert!(
        (left[0] - 0.75).abs() < 0.01 && left[2] < 0.01,
        "left of the back wall: {left:?}"
    );
    assert!(
        (right[2] - 0.75).abs() < 0.01 && right[0] < 0.01,
        "right of the back wall: {right:?}"
    );
}
