//! The stress scenes in `assets/` load, and match the code that generates
//! them (`examples/stress_scenes.rs`, `isr::bench::scenes`).

mod common;

use common::assert_light_and_camera_agree;
use isr::bench::scenes;

#[test]
fn every_stress_scene_asset_loads_and_matches_its_generator() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    for s in scenes::SCENES {
        let path = dir.join(format!("{}.gltf", s.name));
        let loaded = isr::scene::gltf_load::load_with(&path, &Default::default())
            .unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
        let built = scenes::build(s.name).unwrap();
        assert_eq!(
            loaded.triangle_count(),
            built.triangle_count(),
            "{}",
            s.name
        );
        // Small enough for lavapipe: a few hundred triangles at most.
        assert!(built.triangle_count() <= 500, "{}", s.name);
        let duration = loaded
            .animation_duration()
            .expect("every scene is animated");
        assert!((duration - built.animation_duration().unwrap()).abs() < 1e-6);
        for t in [0.0, 0.7, 1.9, duration] {
            let (a, b) = (loaded.state_at(t), built.state_at(t));
            assert_light_and_camera_agree(&a, &b, 1e-4, 1e-4, &format!("{} at {t}", s.name));
            // Instances are compared as placed in the world.
            let pos = |sc: &isr::scene::Scene, st: &isr::scene::FrameState| -> Vec<glam::Vec3> {
                let mut v: Vec<glam::Vec3> = sc
                    .instances
                    .iter()
                    .zip(&st.instance_transforms)
                    .flat_map(|(i, m)| {
                        sc.meshes[i.mesh]
                            .vertices
                            .iter()
                            .map(move |x| m.transform_point3(glam::Vec3::from(x.position)))
                    })
                    .collect();
                v.sort_by(|p, q| p.to_array().partial_cmp(&q.to_array()).unwrap());
                v
            };
            let (pa, pb) = (pos(&loaded, &a), pos(&built, &b));
            assert_eq!(pa.len(), pb.len());
            assert!(
                pa.iter().zip(&pb).all(|(p, q)| p.abs_diff_eq(*q, 1e-4)),
                "{} geometry at {t}",
                s.name
            );
        }
        // Something moves between the bench's first frames.
        assert_ne!(
            built.state_at(s.start),
            built.state_at(s.start + 1.0 / s.fps),
            "{}",
            s.name
        );
    }
}

#[test]
fn unknown_scene_names_list_the_bench_scenes() {
    let e = scenes::build("atrium").unwrap_err().to_string();
    assert!(
        e.contains("cornell, fine, hall, slats, moving-block"),
        "{e}"
    );
}
