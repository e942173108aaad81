//! Writing results: the checks of every output path before any work, and
//! the atomic write every file goes through.
//!
//! Every file is written to a temporary name in its own folder, flushed to
//! disk and renamed over the final path, so an interrupted or failed write
//! never leaves a truncated file where a good one was. [`check_outputs`]
//! checks the paths before any rendering, so bad ones fail in a second rather
//! than after the render.
//!
//! An output that is a symbolic link is written through: the new file
//! replaces the link's target, and the link stays ([`resolve_links`]).
//! The temporaries' names, the list of this process's live ones and the
//! sweep of a dead process's are in `temporaries`; the image formats
//! (OpenEXR, PNG, GIF) in `images`.

mod images;
mod temporaries;

pub use images::{write_exr, write_gif, write_png};
pub use temporaries::abandon_temporaries;

use anyhow::{anyhow, bail, Context as _, Result};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use temporaries::{forget_temporary, name_too_long, temp_file};

/// What a file holds, which fixes its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputKind {
    /// `--out`: the multi-layer OpenEXR.
    Exr,
    /// `--png`: the tonemapped image.
    Png,
    /// `--timings`: the JSON report.
    Json,
    /// `--debug-view`: a PNG named after `--png`.
    DebugPng,
}

impl OutputKind {
    pub fn extension(self) -> &'static str {
        match self {
            OutputKind::Exr => "exr",
            OutputKind::Png | OutputKind::DebugPng => "png",
            OutputKind::Json => "json",
        }
    }

    fn option(self) -> &'static str {
        match self {
            OutputKind::Exr => "--out",
            OutputKind::Png => "--png",
            OutputKind::Json => "--timings",
            OutputKind::DebugPng => "--debug-view",
        }
    }
}

/// The checks of [`check_outputs`] for the render command's outputs.
pub fn check_render_outputs(exr: &Path, png: &Path, timings: Option<&Path>) -> Result<()> {
    let mut outputs = vec![(OutputKind::Exr, exr), (OutputKind::Png, png)];
    outputs.extend(timings.map(|t| (OutputKind::Json, t)));
    check_outputs(&outputs)
}

/// Checks, before any work, that each output can be written where asked: the
/// extension matches its kind, the path (through any symbolic links) is not
/// a directory or other non-file, its folder exists or can be created (it is
/// created) and is writable (a temporary file is created and removed), its
/// name is within the file system's limit, and no two outputs share a path.
pub fn check_outputs(outputs: &[(OutputKind, &Path)]) -> Result<()> {
    let mut seen: Vec<(PathBuf, OutputKind, &Path)> = Vec::new();
    for &(kind, path) in outputs {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !ext.eq_ignore_ascii_case(kind.extension()) {
            bail!(
                "{} {}: the file name must end in .{} (the output is {})",
                kind.option(),
                path.display(),
                kind.extension(),
                match kind {
                    OutputKind::Exr => "an OpenEXR image",
                    OutputKind::Png | OutputKind::DebugPng => "a PNG image",
                    OutputKind::Json => "JSON",
                }
            );
        }
        let key = check_output(kind.option(), path, None)?;
        if let Some((_, other, other_path)) = seen.iter().find(|(k, _, _)| *k == key) {
            bail!(
                "{} {} and {} {} are the same file; give each output its own path",
                other.option(),
                other_path.display(),
                kind.option(),
                path.display()
            );
        }
        seen.push((key, kind, path));
    }
    Ok(())
}

/// The checks of [`check_outputs`] but the extension's for one file,
/// `label` naming it in messages (`--png`); `remedy` replaces the advice
/// ("name a file") where the name is not the user's to choose. Returns the
/// path two spellings of the same file agree on.
pub fn check_output(label: &str, path: &Path, remedy: Option<&str>) -> Result<PathBuf> {
    let target = resolve_links(path).with_context(|| format!("{label} {}", path.display()))?;
    // What the messages call the file: the path given, and where a link
    // leads, the target too.
    let named = if target == path {
        format!("{label} {}", path.display())
    } else {
        format!(
            "{label} {} (a link to {})",
            path.display(),
            target.display()
        )
    };
    if let Ok(meta) = std::fs::metadata(&target) {
        if meta.is_dir() {
            bail!(
                "{named} is a directory; {}",
                remedy.unwrap_or("name a file inside it")
            );
        }
        if !meta.is_file() {
            bail!(
                "{named} exists and is not a regular file (a device or FIFO?); {}",
                remedy.unwrap_or("name a file")
            );
        }
    }
    let dir = folder(&target);
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("{named}: cannot create its folder {}", dir.display()))?;
    let name_bytes = target.file_name().map_or(0, |n| n.len());
    let max = name_max(&dir);
    if name_bytes > max {
        bail!(
            "{named}: the file name is {name_bytes} bytes long; the file system of {} allows at \
             most {max}",
            dir.display()
        );
    }
    // Writability is what creating a file there says, not the mode bits
    // (root, ACLs, read-only mounts).
    let probe = match temp_file(&target) {
        Ok(probe) => probe,
        Err(e) if name_too_long(&e) => return Err(e.context(named)),
        Err(e) => {
            return Err(e.context(format!(
                "{named}: its folder {} is not writable",
                dir.display()
            )))
        }
    };
    drop(probe.1);
    forget_temporary(&probe.0, true);
    identity(&target)
}

/// Checks, before any work, that `--sequence DIR` is a folder (created if
/// missing) that can be written.
pub fn check_sequence_dir(dir: &Path) -> Result<()> {
    if std::fs::metadata(dir).is_ok_and(|m| !m.is_dir()) {
        bail!(
            "--sequence {}: it exists and is not a folder",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("--sequence {}: cannot create the folder", dir.display()))?;
    let probe = temp_file(&dir.join("frame_0000.exr"))
        .with_context(|| format!("--sequence {}: the folder is not writable", dir.display()))?;
    drop(probe.1);
    forget_temporary(&probe.0, true);
    Ok(())
}

/// The folder a path's file is in ("." for a bare name).
fn folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// A path two spellings of the same file agree on: the canonical folder (it
/// exists by now) and the file name, or the canonical file when it exists
/// (a symbolic link to another output).
fn identity(path: &Path) -> Result<PathBuf> {
    if let Ok(p) = std::fs::canonicalize(path) {
        return Ok(p);
    }
    let dir = std::fs::canonicalize(folder(path))
        .with_context(|| format!("cannot resolve the folder of {}", path.display()))?;
    let name = path
        .file_name()
        .ok_or_else(|| anyhow!("{} does not name a file", path.display()))?;
    Ok(dir.join(name))
}

/// The path `path` writes to: itself, or where its chain of symbolic links
/// ends (a target that does not exist yet included: it is created, as a
/// shell's `>` would). Only the last component is followed here; links in
/// the folders are the system's to follow.
pub fn resolve_links(path: &Path) -> Result<PathBuf> {
    let mut p = path.to_path_buf();
    // Linux's own limit on links followed in one lookup.
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = std::fs::read_link(&p)
                    .with_context(|| format!("cannot read the symbolic link {}", p.display()))?;
                // An absolute target replaces the folder.
                p = folder(&p).join(target);
            }
            _ => return Ok(p),
        }
    }
    bail!("too many levels of symbolic links")
}

/// The longest file name `dir`'s file system takes, in bytes.
fn name_max(dir: &Path) -> usize {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt as _;
        if let Ok(c) = std::ffi::CString::new(dir.as_os_str().as_bytes()) {
            // SAFETY: a valid NUL-terminated path; pathconf only reads it.
            let n = unsafe { libc::pathconf(c.as_ptr(), libc::_PC_NAME_MAX) };
            if n > 0 {
                return n as usize;
            }
        }
    }
    255
}

/// How long each write waits between its last byte and its rename
/// (`ISR_TEST_WRITE_PAUSE_MS`, a test hook: an interruption can then be
/// sent while a temporary certainly exists).
fn write_pause() -> Option<std::time::Duration> {
    static PAUSE: std::sync::OnceLock<Option<std::time::Duration>> = std::sync::OnceLock::new();
    *PAUSE.get_or_init(|| {
        let ms: u64 = std::env::var(WRITE_PAUSE_ENV).ok()?.parse().ok()?;
        Some(std::time::Duration::from_millis(ms))
    })
}

/// The test hook of [`write_pause`].
pub const WRITE_PAUSE_ENV: &str = "ISR_TEST_WRITE_PAUSE_MS";

/// Writes `path` through `write` on a temporary file that is synced and then
/// renamed into place; on any error the temporary file is removed and `path`
/// is untouched. A `path` that is a symbolic link is written through: its
/// target is replaced and the link kept.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<()>,
) -> Result<()> {
    let target = resolve_links(path).with_context(|| format!("cannot write {}", path.display()))?;
    let dir = folder(&target);
    std::fs::create_dir_all(&dir).with_context(|| {
        format!(
            "cannot create directory {} for {}",
            dir.display(),
            path.display()
        )
    })?;
    if std::fs::metadata(&target).is_ok_and(|m| !m.is_file()) {
        bail!(
            "cannot write {}: it exists and is not a regular file",
            path.display()
        );
    }
    let (tmp, file) =
        temp_file(&target).with_context(|| format!("cannot write {}", path.display()))?;
    let result = (|| {
        let mut w = std::io::BufWriter::new(file);
        write(&mut w)?;
        w.flush()?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        if let Some(pause) = write_pause() {
            std::thread::sleep(pause);
        }
        std::fs::rename(&tmp, &target)?;
        Ok(())
    })();
    forget_temporary(&tmp, result.is_err());
    result.map_err(|e: anyhow::Error| anyhow!("cannot write {}: {e:#}", path.display()))
}

/// Text (the timings JSON) written as [`write_atomic`] does.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, |w| Ok(w.write_all(text.as_bytes())?))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("isr-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let d = dir("fail");
        let p = d.join("a.png");
        std::fs::write(&p, b"old").unwrap();
        let e = write_atomic(&p, |w| {
            w.write_all(b"partial")?;
            bail!("interrupted")
        })
        .unwrap_err();
        assert!(format!("{e:#}").contains("interrupted"));
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(
            std::fs::read_dir(&d).unwrap().count(),
            1,
            "temporary left behind"
        );
        write_text(&p, "new").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
    }

    #[test]
    fn outputs_are_checked_before_rendering() {
        let d = dir("check");
        let exr = d.join("sub/r.exr");
        let png = d.join("sub/r.png");
        check_render_outputs(&exr, &png, Some(&d.join("t.json"))).unwrap();
        assert!(d.join("sub").is_dir(), "the folder is created");
        assert_eq!(std::fs::read_dir(d.join("sub")).unwrap().count(), 0);
        let err = |e: Result<()>| format!("{:#}", e.unwrap_err());
        let e = err(check_render_outputs(&exr, &d.join("r.exr"), None));
        assert!(e.contains("--png") && e.contains("must end in .png"), "{e}");
        let e = err(check_render_outputs(&exr, &png, Some(&d.join("t.txt"))));
        assert!(e.contains("--timings") && e.contains(".json"), "{e}");
        check_render_outputs(&d.join("x.EXR"), &d.join("./x.png"), None).unwrap();
        std::fs::create_dir_all(d.join("dir.png")).unwrap();
        let e = err(check_render_outputs(&exr, &d.join("dir.png"), None));
        assert!(e.contains("is a directory"), "{e}");
        std::fs::write(d.join("file"), b"").unwrap();
        let e = err(check_render_outputs(&d.join("file/r.exr"), &png, None));
        assert!(e.contains("cannot create its folder"), "{e}");
        // The same file spelled twice, and through a symbolic link.
        let e = err(check_outputs(&[
            (OutputKind::Png, &png),
            (OutputKind::Png, &d.join("sub/../sub/r.png")),
        ]));
        assert!(e.contains("are the same file"), "{e}");
        #[cfg(unix)]
        {
            std::fs::write(&png, b"x").unwrap();
            std::os::unix::fs::symlink(&png, d.join("link.png")).unwrap();
            let e = err(check_outputs(&[
                (OutputKind::Png, &png),
                (OutputKind::Png, &d.join("link.png")),
            ]));
            assert!(e.contains("are the same file"), "{e}");
        }
    }
}
