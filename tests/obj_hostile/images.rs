//! What a hostile OBJ renders: normals against the winding, of zero, tiny
//! or huge length, texture coordinates at and past their limit, and the
//! order of a material's triangles. Rendered in process.

use crate::common::{self, temp_dir};
use glam::Vec3;
use isr::readback::Readback;
use isr::scene::obj_load;

/// A unit box's faces, each counter-clockwise seen from outside, and their
/// outward normals.
const BOX: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 -1\nv 1 0 -1\nv 1 1 -1\nv 0 1 -1\n";
const FACES: [([usize; 4], [i32; 3]); 6] = [
    ([1, 2, 3, 4], [0, 0, 1]),
    ([6, 5, 8, 7], [0, 0, -1]),
    ([2, 6, 7, 3], [1, 0, 0]),
    ([5, 1, 4, 8], [-1, 0, 0]),
    ([4, 3, 7, 8], [0, 1, 0]),
    ([5, 6, 2, 1], [0, -1, 0]),
];

/// The box with its faces wound outward or inward and its normals pointing
/// out or in.
fn box_obj(wound_out: bool, normals_out: bool) -> String {
    let mut obj = BOX.to_string();
    for (_, n) in FACES {
        let s = if normals_out { 1 } else { -1 };
        obj += &format!("vn {} {} {}\n", s * n[0], s * n[1], s * n[2]);
    }
    for (k, (mut f, _)) in FACES.into_iter().enumerate() {
        if !wound_out {
            f.reverse();
        }
        obj += "f";
        for v in f {
            obj += &format!(" {v}//{}", k + 1);
        }
        obj += "\n";
    }
    obj
}

/// `obj` rendered from above its front right corner, lit by a point light
/// there (the default light above a box leaves its sides dark).
fn render(dir: &std::path::Path, obj: &str, method: &'static str) -> Readback {
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    let mut scene = obj_load::load(&dir.join("scene.obj")).unwrap();
    scene.camera = isr::scene::Camera::look_at(
        Vec3::new(2.5, 2.5, 2.0),
        Vec3::new(0.5, 0.5, -0.5),
        Vec3::Y,
        40f32.to_radians(),
        0.05,
    );
    scene.lights = vec![common::point(Vec3::new(2.0, 3.0, 2.5), 20.0)];
    let gpu = common::gpu();
    common::render(&gpu, &scene, &common::sized(method, 48, 48, 64), 1).readback
}

fn mean(pixels: &[[f32; 4]]) -> f64 {
    pixels
        .iter()
        .map(|p| (p[0] + p[1] + p[2]) as f64)
        .sum::<f64>()
        / pixels.len() as f64
}

/// A box whose normals point in while its faces are wound out, or the
/// other way round, is lit as the box whose winding and normals agree
/// (both rendered black before: shading flips the normal of a face seen
/// from behind, which turned the file's normal away from the viewer). A
/// face wound against its normals is turned, so both are that box.
#[test]
fn a_box_wound_against_its_normals_is_lit_as_one_wound_with_them() {
    let dir = temp_dir("obj-wound");
    let agree = render(&dir, &box_obj(true, true), "none");
    assert!(mean(&agree.direct) > 0.01, "the box is lit");
    for (wound_out, normals_out) in [(true, false), (false, true)] {
        let other = render(&dir, &box_obj(wound_out, normals_out), "none");
        // The same triangles, turned: the same pixels, the same normals.
        let (a, b) = (mean(&agree.direct), mean(&other.direct));
        assert!(
            (a - b).abs() <= 1e-3 * a,
            "wound out {wound_out}, normals out {normals_out}: mean direct {b}, not {a}"
        );
    }
}

/// `vn` of length 1e-30 and 1e30 is normalised (both became +Y, whatever
/// their direction: their squares leave f32); `vn 0 0 0` gives its faces
/// computed normals (it became +Y too).
#[test]
fn normals_of_tiny_huge_and_zero_length() {
    let dir = temp_dir("obj-vn");
    // A wall in the plane x = 0 facing +X, with the file's normals; and one
    // facing -X whose normal is zero.
    let obj = "v 0 0 0\nv 0 1 0\nv 0 0 1\nv 0 1 1\nvn 1e-30 0 0\nvn 1e30 0 0\nvn 0 0 0\nf 1//1 2//2 3//1\nf 1//3 3//3 4//3\n";
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    let scene = obj_load::load(&dir.join("scene.obj")).unwrap();
    let mesh = &scene.meshes[0];
    let mut faces = 0;
    for t in mesh.indices.chunks_exact(3) {
        let v = |k: usize| &mesh.vertices[t[k] as usize];
        let p: Vec<Vec3> = (0..3).map(|k| Vec3::from(v(k).position)).collect();
        // The second face is the one with the corner (0, 1, 1).
        let want = if p.contains(&Vec3::new(0.0, 1.0, 1.0)) {
            -Vec3::X
        } else {
            Vec3::X
        };
        for k in 0..3 {
            assert_eq!(Vec3::from(v(k).normal), want, "{p:?}");
        }
        faces += 1;
    }
    assert_eq!(faces, 2);
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.contains("1 normal(s) of zero length")),
        "{:#?}",
        scene.warnings
    );
}

/// A texture coordinate past `Limits::texcoord` is refused at its line
/// (`vt 3e38 -3e38` made every pixel NaN, exit 0); at the limit a textured
/// quad renders without NaN.
#[test]
fn texture_coordinates_past_their_limit_are_refused_and_at_it_render() {
    let dir = temp_dir("obj-vt");
    std::fs::write(
        dir.join("t.png"),
        common::gltf::png(2, 2, &[255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]),
    )
    .unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl a\nmap_Kd t.png\n").unwrap();
    let quad = |vt: &str| {
        format!(
            "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\n{vt}f 1/1 2/2 3/3 4/4\n"
        )
    };
    let e = obj_load::load_bytes(
        &dir.join("scene.obj"),
        quad("vt 0 0\nvt 3e38 -3e38\n").as_bytes(),
        &Default::default(),
    )
    .unwrap_err();
    let e = format!("{e:#}");
    assert!(
        e.contains("scene.obj line 8: texture coordinate 2 is (3e38, -3e38)")
            && e.contains("up to 65536"),
        "{e}"
    );
    let m = isr::scene::limits::Limits::DEFAULT.texcoord;
    let image = render(
        &dir,
        &quad(&format!(
            "vt {m} {m}\nvt -{m} {m}\nvt -{m} -{m}\nvt {m} -{m}\n"
        )),
        "none",
    );
    assert!(common::geometry_pixels(&image) > 100, "the quad is in view");
    for (layer, pixels) in [("final", &image.final_radiance), ("direct", &image.direct)] {
        let nan = pixels
            .iter()
            .filter(|p| !p.iter().all(|c| c.is_finite()))
            .count();
        assert_eq!(nan, 0, "{nan} {layer} pixels are not finite");
    }
}

/// A material's triangles are one mesh in the file's order, where groups
/// and material switches split them into meshes before: the order in which
/// triangles are drawn changes nothing but which of two surfaces at exactly
/// the same depth a pixel shows (none here). The box on a floor drawn in
/// its faces' order and in the reverse order renders the same, bit for
/// bit, with direct and indirect light.
#[test]
fn the_order_of_a_materials_triangles_changes_no_pixel() {
    let dir = temp_dir("obj-order");
    // The box on a floor (vertices 9 to 12), which lights its sides
    // indirectly; the faces are the last 7 lines.
    let floor = "v -2 -0.01 2\nv 3 -0.01 2\nv 3 -0.01 -3\nv -2 -0.01 -3\n";
    let forward = box_obj(true, true).replacen(BOX, &format!("{BOX}{floor}"), 1) + "f 9 10 11 12\n";
    let mut lines: Vec<&str> = forward.lines().collect();
    let faces = lines.split_off(lines.len() - 7);
    let reversed = format!(
        "{}\n{}\n",
        lines.join("\n"),
        faces
            .iter()
            .rev()
            .map(|f| format!("g split\n{f}"))
            .collect::<Vec<_>>()
            .join("\n")
    );
    for method in ["none", "multires-gather", "hisr"] {
        let (a, b) = (
            render(&dir, &forward, method),
            render(&dir, &reversed, method),
        );
        for (layer, x, y) in [
            ("direct", &a.direct, &b.direct),
            ("indirect", &a.indirect, &b.indirect),
        ] {
            let differ = x.iter().zip(y).filter(|(p, q)| p != q).count();
            assert_eq!(differ, 0, "{method}: {differ} pixels of {layer} differ");
        }
    }
}
