//! Bare scenes (an OBJ without a description, `--light` or `--camera`)
//! get a camera and a light placed by looking at them (`placement`,
//! docs/guide.md section 2, "A bare scene"): flat scenes and a scene with a
//! stray triangle far away are seen and lit, the line printed says how to
//! keep the placement, and what the command line gives is kept.
mod common;

use common::framing::render_bare;
use common::temp_dir;
use std::path::{Path, PathBuf};

fn obj(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(format!("{name}.obj"));
    std::fs::write(&path, text).unwrap();
    path
}

/// A 1 m cube on the floor (12 triangles) as OBJ lines, after `first` vertices.
fn cube(first: usize) -> String {
    let mut s = String::new();
    for i in 0..8 {
        let c = |b: usize| if i & b != 0 { 0.5 } else { -0.5 };
        s += &format!("v {} {} {}\n", c(1), c(2) + 0.5, c(4));
    }
    for q in [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ] {
        let v = |k: usize| q[k] + first + 1;
        s += &format!(
            "f {} {} {}\nf {} {} {}\n",
            v(0),
            v(1),
            v(2),
            v(0),
            v(2),
            v(3)
        );
    }
    s
}

/// Each flat case, rendered bare at 48x48 with the default method: a
/// tenth of the image or more shows its surface (a triangle framed by its
/// bounding sphere fills about a fifth seen square on, less at a slant),
/// and at least half of that is lit. The spot the loader places alone
/// lands under the horizontal triangle, in the vertical one's plane, and 5
/// km under the box: none of them was lit.
#[test]
fn flat_scenes_and_a_stray_triangle_far_away_are_framed_and_lit() {
    let dir = temp_dir("bare-flat");
    let cases = [
        (
            "horizontal",
            "v -1 0 -1\nv 1 0 -1\nv 0 0 1\nf 1 2 3\n".to_string(),
        ),
        (
            "vertical",
            "v -1 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n".to_string(),
        ),
        (
            "stray",
            cube(0) + "v 100000 0 0\nv 100000.3 0 0\nv 100000 0.3 0\nf 9 10 11\n",
        ),
    ];
    for (name, text) in cases {
        let scene = obj(&dir, name, &text);
        let seen = render_bare(&dir, name, &scene, 48, &[]);
        assert!(
            seen.geometry * 10 >= seen.pixels && seen.lit * 2 >= seen.geometry,
            "{name}: {seen:?}"
        );
        assert!(seen.stderr.contains("placed"), "{name}: {}", seen.stderr);
        if name == "stray" {
            // The cube fills the view (its bounding sphere does), not the
            // 100 km between it and the triangle.
            assert!(seen.geometry * 4 >= seen.pixels, "{name}: {seen:?}");
        }
    }
}

/// The printed `--camera` and `--light` give the same image: a user keeps
/// the placement by copying them.
#[test]
fn the_printed_camera_and_light_reproduce_the_placement() {
    let dir = temp_dir("bare-keep");
    let scene = obj(&dir, "cube", &cube(0));
    let bare = render_bare(&dir, "bare", &scene, 32, &[]);
    let line = bare
        .stderr
        .lines()
        .find(|l| l.contains("keep or change them with"))
        .unwrap_or_else(|| panic!("{}", bare.stderr));
    let kept: Vec<&str> = line
        .split("keep or change them with ")
        .nth(1)
        .unwrap()
        .split(' ')
        .collect();
    assert_eq!(kept.len(), 4, "{line}");
    assert_eq!((kept[0], kept[2]), ("--camera", "--light"), "{line}");
    let again = render_bare(&dir, "kept", &scene, 32, &kept);
    // Nothing placed the second time: the command line gave both.
    assert!(!again.stderr.contains("placed"), "{}", again.stderr);
    let a = image::open(dir.join("bare.png")).unwrap().to_rgb8();
    let b = image::open(dir.join("kept.png")).unwrap().to_rgb8();
    // Printed to four significant digits: the views differ by under a
    // ten-thousandth of the scene, a pixel's colour by a few levels at
    // most where an edge moves.
    let differ = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 8))
        .count();
    assert!(differ * 50 <= a.pixels().len(), "{differ} pixels differ");
}
