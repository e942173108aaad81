//! `cargo bench --bench gallery`: the pictures the README and docs/gallery.md
//! show, each from one `isr render` command that the page prints beside it.
//!
//! - `assets/cornell.png`: what the README's first command writes;
//! - `docs/gallery/NAME.png`: each archive scene from its description
//!   (`assets/archive/NAME.scene.json`), the default method, 512x512;
//! - `docs/gallery/NAME-bare.png`: the same OBJ with no description, framed
//!   and lit by `isr` alone (the line saying what it placed goes on the page).
//!
//! The archive scenes are read from `$ISR_SCENES` or `../shared/scenes`; a
//! scene that is not there is left out with a note (its old picture stays).
//! Minutes on lavapipe: each render is printed as it starts.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The archive scenes in gallery order, with the file their archive holds.
const SCENES: [(&str, &str); 4] = [
    ("sponza", "sponza/sponza.obj"),
    ("sibenik", "sibenik/sibenik.obj"),
    ("conference", "conference/conference.obj"),
    ("bunny", "bunny/bunny.obj"),
];

/// Every gallery render: the default method at 512x512, an RSM of 512, the
/// middle of the descriptions' 8 s animations.
const SIZE: [&str; 8] = [
    "--width", "512", "--height", "512", "--rsm", "512", "--time", "4",
];

/// The credits the archive's README gives, shown under the gallery.
const CREDITS: &str = "Sponza atrium and Sibenik cathedral by Marko Dabrovic (Sibenik's \
holes corrected by Kenzie Lamar at Vicarious Visions, its textures and bump maps painted \
by Morgan McGuire); Greg Ward's conference room, recreated by Kenzie Lamar; the Stanford \
bunny from the Stanford 3D Scanning Repository. Third-party data, read from the archive \
folder and never copied into this repository.";

struct Shot {
    command: String,
    /// What `isr` said it placed, for a bare scene.
    placed: Vec<String>,
}

/// Runs `isr render` with `args`, writing `png`; its command line as the page
/// shows it (the repository-relative paths, `isr` for the binary).
fn render(root: &Path, args: &[&str], png: &str) -> anyhow::Result<Shot> {
    let mut all: Vec<&str> = vec!["render"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--png", png]);
    let command = format!("isr {}", all.join(" "));
    eprintln!("gallery: {command}");
    let exr = std::env::temp_dir().join("isr-gallery.exr");
    let out = Command::new(env!("CARGO_BIN_EXE_isr"))
        .current_dir(root)
        .args(&all)
        .arg("--out")
        .arg(&exr)
        .output()?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    anyhow::ensure!(
        out.status.success(),
        "`{command}` failed ({}):\n{stderr}",
        out.status
    );
    let placed = stderr
        .lines()
        .filter(|l| l.contains("placed") || l.contains("--light") || l.contains("--camera"))
        .map(str::to_owned)
        .collect();
    Ok(Shot { command, placed })
}

fn main() -> anyhow::Result<()> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let archive = isr::scene::description::archive_root();
    std::fs::create_dir_all(root.join("docs/gallery"))?;
    // The README's first command, as the README gives it.
    let first = render(&root, &[], "assets/cornell.png")?;
    let mut md = String::from(
        "# Gallery\n\nWritten by `cargo bench --bench gallery`: each picture is one `isr \
render` command, shown under it. The archive scenes at the middle of their descriptions' \
animations, the default method (HISR at its best balance, with the voxel grid), 512x512, \
RSM 512; beside each, the same OBJ opened bare: no description, framed and lit by `isr` \
alone.\n\n",
    );
    md += &format!(
        "The built-in box, the README's first command (`{}`):\n\n![the built-in box](../assets/cornell.png)\n\n",
        first.command
    );
    for (name, file) in SCENES {
        if !archive.join(file).is_file() {
            eprintln!(
                "gallery: {} is not in {}: left out",
                file,
                archive.display()
            );
            continue;
        }
        let described = format!("assets/archive/{name}.scene.json");
        let mut args = vec!["--scene", described.as_str()];
        args.extend_from_slice(&SIZE);
        let shot = render(&root, &args, &format!("docs/gallery/{name}.png"))?;
        let obj = archive.join(file).to_string_lossy().into_owned();
        let mut args = vec!["--scene", obj.as_str()];
        args.extend_from_slice(&SIZE[..6]);
        let bare = render(&root, &args, &format!("docs/gallery/{name}-bare.png"))?;
        md += &format!(
            "## {name}\n\n| from its description | bare |\n| --- | --- |\n\
             | ![{name}](gallery/{name}.png) | ![{name}, bare](gallery/{name}-bare.png) |\n\n\
             Described: `{}`\n\nBare: `{}`",
            shot.command,
            bare.command.replace(&obj, &format!("$ISR_SCENES/{file}"))
        );
        if bare.placed.is_empty() {
            md += "\n\n";
        } else {
            md += &format!(
                "; `isr` said:\n\n```\n{}\n```\n\n",
                bare.placed
                    .join("\n")
                    .replace(&obj, &format!("$ISR_SCENES/{file}"))
            );
        }
    }
    md += &format!("{CREDITS}\n");
    std::fs::write(root.join("docs/gallery.md"), md)?;
    eprintln!("gallery: wrote docs/gallery.md");
    Ok(())
}
