//! Memory in proportion to the file: a library named thousands of times,
//! a million groups or material switches, too many materials or distinct
//! vertices, warnings by the million. Each runs in process, where the
//! bytes allocated (this thread's peak) and read can be counted.

use crate::common::measure::{bytes_read, peak_allocated};
use crate::common::temp_dir;
use isr::scene::limits::Limits;
use isr::scene::{load_file, obj_load, LoadOptions};

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 1 0 -1\n";

/// A library of `n` materials `m0`..: about 25 bytes each.
fn library(n: usize) -> String {
    (0..n)
        .map(|i| format!("newmtl m{i}\nKd 0.5 0.5 0.5\n"))
        .collect()
}

/// 2,000 `mtllib` lines and one line naming the library 2,000 times: the
/// library is read once, and nothing is held per naming (tobj merged its
/// 100 materials again at each, 200 MB here and 4.2 GB, then an abort, at
/// 20,000).
#[test]
fn a_library_named_thousands_of_times_is_read_once() {
    let dir = temp_dir("obj-mtllib-many");
    let lib = library(100);
    std::fs::write(dir.join("lib.mtl"), &lib).unwrap();
    let obj = format!(
        "{TRIANGLE}{}mtllib{}\nusemtl m7\nf 1 2 3\n",
        "mtllib lib.mtl\n".repeat(2000),
        " lib.mtl".repeat(2000)
    );
    std::fs::write(dir.join("scene.obj"), &obj).unwrap();
    let ((scene, read), peak) =
        peak_allocated(|| bytes_read(|| obj_load::load(&dir.join("scene.obj")).unwrap()));
    assert_eq!(scene.materials.len(), 1);
    assert_eq!(scene.materials[0].name, "m7");
    // The OBJ, the library once, and a few reads of metadata.
    let files = (obj.len() + lib.len()) as u64;
    assert!(read < files + (16 << 10), "read {read} bytes of {files}");
    // A line and the library at a time, and the library's materials (a
    // few words each): well under 1 MiB; tobj's merges took 200 MB.
    assert!(peak < 1 << 20, "allocated {} KiB", peak >> 10);
}

/// 100,000 `g` lines sharing one triangle, and 100,000 `usemtl` switches
/// between two materials: one mesh per material, and memory in proportion
/// to the triangles (12 bytes each in the mesh), not a mesh per group or
/// per switch (about 2 KB each before).
#[test]
fn groups_and_material_switches_make_one_mesh_per_material() {
    let dir = temp_dir("obj-groups");
    std::fs::write(dir.join("lib.mtl"), library(2)).unwrap();
    let n = 100_000;
    let groups = format!(
        "{TRIANGLE}{}",
        (0..n)
            .map(|i| format!("g g{i}\nf 1 2 3\n"))
            .collect::<String>()
    );
    let switches = format!(
        "{TRIANGLE}mtllib lib.mtl\n{}",
        "usemtl m0\nf 1 2 3\nusemtl m1\nf 1 3 2\n".repeat(n / 2)
    );
    for (name, obj, meshes) in [("groups.obj", groups, 1), ("switches.obj", switches, 2)] {
        std::fs::write(dir.join(name), &obj).unwrap();
        let (scene, peak) = peak_allocated(|| obj_load::load(&dir.join(name)).unwrap());
        assert_eq!(scene.meshes.len(), meshes, "{name}");
        assert_eq!(scene.triangle_count(), n, "{name}");
        // The triangles' indices (12 bytes each) and the crease normals'
        // work on them (8 more), in vectors up to twice their length while
        // they grow: under 64 bytes a triangle. A mesh per group or switch
        // took about 1 KB each.
        assert!(
            peak < 64 * n,
            "{name}: allocated {} KiB for {n} triangles",
            peak >> 10
        );
    }
}

/// Materials count against `Limits::materials` as a library defines them:
/// refused at the `newmtl` line that passes it (a 64 MB library of 4
/// million materials took 5 GB and 31 s), with memory for the budget's
/// materials only.
#[test]
fn too_many_materials_are_refused_at_their_line() {
    let dir = temp_dir("obj-materials");
    std::fs::write(dir.join("lib.mtl"), library(20_000)).unwrap();
    std::fs::write(
        dir.join("scene.obj"),
        format!("{TRIANGLE}mtllib lib.mtl\nusemtl m1\nf 1 2 3\n"),
    )
    .unwrap();
    let options = LoadOptions {
        limits: Limits {
            materials: 1000,
            ..Limits::DEFAULT
        },
        ..Default::default()
    };
    let (e, peak) =
        peak_allocated(|| obj_load::load_with(&dir.join("scene.obj"), &options).unwrap_err());
    let e = format!("{e:#}");
    // Material 1001 is defined at line 2001 (two lines each).
    assert!(
        e.contains("scene.obj line 4: mtllib lib.mtl: lib.mtl line 2001")
            && e.contains("more than 1000 materials; the limit is 1000"),
        "{e}"
    );
    // The library's bytes (about 500 KB, read whole) and 1000 materials.
    assert!(peak < 1 << 20, "allocated {} KiB", peak >> 10);
    assert_eq!(Limits::DEFAULT.materials, 65_536);
}

/// Distinct vertices (position, texture coordinate, normal) count against
/// the budget as faces make them: refused at the face's line, with the
/// file read no further (they were counted after the whole file, 15 s and
/// 2.5 GB for a large one, naming no line).
#[test]
fn distinct_vertices_are_refused_at_the_line_that_passes_the_budget() {
    let dir = temp_dir("obj-distinct");
    // 64 positions and 64 texture coordinates: each face line makes 8 new
    // combinations of them, a position with the next texture coordinate.
    let mut obj = String::new();
    for k in 0..64 {
        // On a paraboloid: no three corners of a face on a line.
        let (x, y) = (k % 8, k / 8);
        obj += &format!("v {x} {y} {}\nvt {} 0\n", x * x + y * y, k as f32 / 64.0);
    }
    let header = obj.lines().count();
    let mut k = 0usize;
    for _ in 0..8000 {
        obj += "f";
        for _ in 0..8 {
            obj += &format!(" {}/{}", 1 + k % 64, 1 + (k / 64) % 64);
            k += 1;
        }
        obj += "\n";
    }
    let path = dir.join("scene.obj");
    std::fs::write(&path, &obj).unwrap();
    let options = LoadOptions {
        limits: Limits {
            vertices: 4000,
            ..Limits::DEFAULT
        },
        ..Default::default()
    };
    let (e, read) = bytes_read(|| obj_load::load_with(&path, &options).unwrap_err());
    let e = format!("{e:#}");
    // Vertex 4001 is made by face 501 (8 a face).
    let line = header + 501;
    assert!(
        e.contains(&format!(
            "scene.obj line {line}: the faces so far make more than 4000 distinct vertices"
        )),
        "{e}"
    );
    // Read up to that line (and a 64 KiB buffer beyond), not the 8000 faces.
    assert!(
        read < (obj.len() as u64) / 2,
        "read {read} of {} bytes",
        obj.len()
    );
}

/// An MTL and an OBJ whose every line asks for a warning of one kind:
/// 5,000 each of duplicate materials, `Kd` above 1, `map_Kd` options,
/// unknown MTL keys, unknown OBJ statements and unknown `usemtl` names.
/// One warning line per kind, each with its count and first line (they
/// were one line each: a 10 MB file printed a million lines).
#[test]
fn one_warning_per_kind_with_its_count() {
    let dir = temp_dir("obj-warnings-once");
    std::fs::write(
        dir.join("t.png"),
        crate::common::gltf::png(1, 1, &[200, 200, 200]),
    )
    .unwrap();
    let n = 5000;
    let mut mtl = String::from("newmtl a\n");
    for i in 0..n {
        mtl += &format!("key{i} 1\nKd 2 0.5 0.5\nmap_Kd -s 2 2 1 t.png\nnewmtl a\n");
    }
    std::fs::write(dir.join("m.mtl"), &mtl).unwrap();
    let mut obj = format!("{TRIANGLE}mtllib m.mtl\nusemtl a\nf 1 2 3\n");
    for i in 0..n {
        obj += &format!("statement{i} 1\nusemtl nothing{i}\nf 1 2 3\n");
    }
    std::fs::write(dir.join("scene.obj"), &obj).unwrap();
    let scene = load_file(&dir.join("scene.obj"), &Default::default()).unwrap();
    let w = &scene.warnings;
    let find = |what: &str| -> &String {
        let found: Vec<&String> = w.iter().filter(|l| l.contains(what)).collect();
        assert_eq!(found.len(), 1, "{what}: {w:#?}");
        found[0]
    };
    let kinds = [
        ("material(s) defined twice", format!("{n} "), "m.mtl line 5"),
        ("Kd value(s) above 1", format!("{n} "), "m.mtl line 3"),
        ("map_Kd option(s) ignored", format!("{n} "), "m.mtl line 4"),
        (
            "MTL keys ignored",
            format!("{} other name(s) ({} time(s))", n - 8, n - 8),
            "'key0' (m.mtl line 2)",
        ),
        (
            "OBJ statements ignored",
            format!("{} other name(s)", n - 8),
            "'statement0' (scene.obj line 7)",
        ),
        (
            "usemtl names no material",
            format!("{} other name(s)", n - 8),
            "'nothing0' (scene.obj line 8)",
        ),
    ];
    for (what, count, first) in &kinds {
        let line = find(what);
        assert!(
            line.contains(count.as_str()) && line.contains(first),
            "{line}"
        );
        assert!(line.len() < 1000, "{} bytes: {line}", line.len());
    }
    // Those kinds, computed normals, the default light and camera.
    assert!(w.len() <= kinds.len() + 3, "{w:#?}");
}
