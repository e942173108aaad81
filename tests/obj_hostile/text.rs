//! The text of a hostile OBJ: a byte-order mark, lone CR line ends, escape
//! sequences, NULs and a 1 MB name, and what the messages say of them.
//! Through the binary where the terminal is the point.

use crate::common::cli::Isr;
use crate::common::temp_dir;
use crate::QUAD;
use isr::scene::obj_load;

/// A byte-order mark before `mtllib` (which it hid: every material was
/// dropped, with a warning naming an invisible character), in the library
/// too, and lone CR line ends (read as one line: "'v' is not a number"):
/// the same scene as plain LF text.
#[test]
fn a_byte_order_mark_and_lone_cr_line_ends_read_as_plain_text() {
    let dir = temp_dir("obj-bom");
    let mtl = "newmtl a\nKd 0.2 0.4 0.6\n";
    let obj = format!("mtllib m.mtl\nusemtl a\n{QUAD}");
    let load = |mtl: &str, obj: &str| {
        std::fs::write(dir.join("m.mtl"), mtl).unwrap();
        std::fs::write(dir.join("scene.obj"), obj).unwrap();
        obj_load::load(&dir.join("scene.obj")).unwrap()
    };
    let plain = load(mtl, &obj);
    let cr = |s: &str| s.replace('\n', "\r");
    for (what, m, o) in [
        ("a BOM", format!("\u{feff}{mtl}"), format!("\u{feff}{obj}")),
        ("CR line ends", cr(mtl), cr(&obj)),
        (
            "a BOM and CR line ends",
            format!("\u{feff}{}", cr(mtl)),
            format!("\u{feff}{}", cr(&obj)),
        ),
    ] {
        let s = load(&m, &o);
        assert_eq!(s.materials.len(), 1, "{what}");
        assert_eq!(s.materials[0].name, "a", "{what}");
        assert_eq!(
            s.materials[0].base_color, plain.materials[0].base_color,
            "{what}"
        );
        assert_eq!(s.meshes[0].vertices, plain.meshes[0].vertices, "{what}");
        assert_eq!(s.meshes[0].indices, plain.meshes[0].indices, "{what}");
        assert_eq!(s.warnings, plain.warnings, "{what}");
    }
}

/// Bytes of the file reach the terminal escaped and cut short: an escape
/// sequence in a vertex line (which cleared the screen), a NUL, a 1 MB
/// library name (a 10 MB one made a 10 MB message), and an unknown
/// statement that sets the terminal's title, in a warning.
#[test]
fn file_bytes_reach_the_terminal_escaped_and_cut_short() {
    let dir = temp_dir("obj-escapes");
    let run = |obj: &[u8]| {
        std::fs::write(dir.join("scene.obj"), obj).unwrap();
        Isr::tiny(&dir).args(["--scene", "scene.obj"]).run()
    };
    let raw = |s: &str| s.contains('\u{1b}') || s.contains('\0') || s.contains('\u{7}');
    for (obj, shows) in [
        (
            b"v 0 0 0\nv 1 \x1b[2J 0\n".to_vec(),
            "'\\u{1b}[2J' is not a number",
        ),
        (b"v 0 0 0\nv 1 \0 0\n".to_vec(), "'\\u{0}' is not a number"),
    ] {
        let ran = run(&obj);
        assert!(!ran.status.success());
        assert!(
            !raw(&ran.stderr)
                && ran.stderr.contains("scene.obj line 2: vertex 2: ")
                && ran.stderr.contains(shows),
            "{:?}",
            ran.stderr
        );
    }
    let long = format!("mtllib {}\n{QUAD}", "n".repeat(1 << 20));
    let ran = run(long.as_bytes());
    assert!(!ran.status.success());
    assert!(
        ran.stderr.len() < 2000 && ran.stderr.contains("(1048576 bytes in all)"),
        "{} bytes: {}",
        ran.stderr.len(),
        &ran.stderr[..ran.stderr.len().min(2000)]
    );
    let ran = run(format!("{QUAD}\u{1b}]0;pwned\u{7} 1\n").as_bytes());
    assert!(ran.status.success(), "{}", ran.stderr);
    assert!(
        !raw(&ran.stderr)
            && ran
                .stderr
                .contains("'\\u{1b}]0;pwned\\u{7}' (scene.obj line 6)"),
        "{:?}",
        ran.stderr
    );
}

/// Each error names the file once (every OBJ error named it twice) with the
/// line, and says what is wrong in words: a corrupt PNG's chunk by its
/// type, not as a Rust debug dump.
#[test]
fn messages_name_the_file_once_and_the_cause_in_words() {
    let dir = temp_dir("obj-messages");
    std::fs::write(
        dir.join("scene.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 0 -1\nf 1 2 4\n",
    )
    .unwrap();
    let e = Isr::tiny(&dir).args(["--scene", "scene.obj"]).fails();
    assert_eq!(e.matches("scene.obj").count(), 1, "{e}");
    assert!(
        e.contains("scene.obj line 4: face vertex '4' refers to vertex 4"),
        "{e}"
    );
    // A PNG whose header chunk's checksum is wrong.
    let mut png = crate::common::gltf::png(2, 2, &[9; 12]);
    png[29] ^= 0x5a;
    std::fs::write(dir.join("bad.png"), png).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl a\nmap_Kd bad.png\n").unwrap();
    std::fs::write(
        dir.join("scene.obj"),
        format!("mtllib m.mtl\nusemtl a\n{QUAD}"),
    )
    .unwrap();
    let e = Isr::tiny(&dir).args(["--scene", "scene.obj"]).fails();
    assert!(
        e.contains("m.mtl line 2: map_Kd bad.png: the texture: cannot decode")
            && e.contains("CRC error")
            && e.contains("chunk IHDR")
            && !e.contains("ChunkType")
            && e.matches("bad.png").count() == 1,
        "{e}"
    );
}
