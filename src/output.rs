//! Writing results: a multi-layer OpenEXR of linear data and a PNG for viewing.
//!
//! Every file is written to a temporary name in its own folder, flushed to
//! disk and renamed over the final path, so an interrupted or failed write
//! never leaves a truncated file where a good one was. [`check_outputs`]
//! checks the paths before any rendering, so bad ones fail in a second rather
//! than after the render.

use crate::readback::Readback;
use anyhow::{anyhow, bail, Context as _, Result};
use exr::prelude::*;
use std::io::Write as _;
use std::path::{Path, PathBuf};

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
/// extension matches its kind, the path is not a directory or other non-file,
/// its folder exists or can be created (it is created) and is writable (a
/// temporary file is created and removed), and no two outputs share a path.
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
        if let Ok(meta) = std::fs::metadata(path) {
            if meta.is_dir() {
                bail!(
                    "{} {} is a directory; name a file inside it",
                    kind.option(),
                    path.display()
                );
            }
            if !meta.is_file() {
                bail!(
                    "{} {} exists and is not a regular file (a device or FIFO?); name a file",
                    kind.option(),
                    path.display()
                );
            }
        }
        let dir = folder(path);
        std::fs::create_dir_all(&dir).with_context(|| {
            format!(
                "{} {}: cannot create its folder {}",
                kind.option(),
                path.display(),
                dir.display()
            )
        })?;
        // Writability is what creating a file there says, not the mode bits
        // (root, ACLs, read-only mounts).
        let probe = temp_file(path).with_context(|| {
            format!(
                "{} {}: its folder {} is not writable",
                kind.option(),
                path.display(),
                dir.display()
            )
        })?;
        drop(probe.1);
        let _ = std::fs::remove_file(&probe.0);
        let key = identity(path)?;
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
    let _ = std::fs::remove_file(&probe.0);
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

/// A new file next to `path` (same folder, so the rename cannot cross file
/// systems), created exclusively so it never clobbers anything.
fn temp_file(path: &Path) -> Result<(PathBuf, std::fs::File)> {
    static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let dir = folder(path);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| anyhow!("{} does not name a file", path.display()))?;
    loop {
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{}-{n}.tmp", std::process::id()));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(anyhow!("cannot create a file in {}: {e}", dir.display())),
        }
    }
}

/// Writes `path` through `write` on a temporary file that is synced and then
/// renamed into place; on any error the temporary file is removed and `path`
/// is untouched.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<()>,
) -> Result<()> {
    let dir = folder(path);
    std::fs::create_dir_all(&dir).with_context(|| {
        format!(
            "cannot create directory {} for {}",
            dir.display(),
            path.display()
        )
    })?;
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        bail!(
            "cannot write {}: it exists and is not a regular file",
            path.display()
        );
    }
    let (tmp, file) =
        temp_file(path).with_context(|| format!("cannot write {}", path.display()))?;
    let result = (|| {
        let mut w = std::io::BufWriter::new(file);
        write(&mut w)?;
        w.flush()?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)?;
        Ok(())
    })();
    result.map_err(|e: anyhow::Error| {
        let _ = std::fs::remove_file(&tmp);
        anyhow!("cannot write {}: {e:#}", path.display())
    })
}

/// Text (the timings JSON) written as [`write_atomic`] does.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, |w| Ok(w.write_all(text.as_bytes())?))
}

fn rgb_layer(name: &str, w: usize, h: usize, data: &[[f32; 4]]) -> Layer<AnyChannels<FlatSamples>> {
    let channel = |c: &str, k: usize| {
        AnyChannel::new(c, FlatSamples::F32(data.iter().map(|p| p[k]).collect()))
    };
    Layer::new(
        (w, h),
        LayerAttributes::named(name),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(vec![
            channel("R", 0),
            channel("G", 1),
            channel("B", 2),
        ])),
    )
}

/// Layers `final`, `direct`, `indirect` (radiance W/(m^2 sr); `indirect` is
/// the irradiance E in W/m^2 before the albedo/pi of the composite), `albedo`,
/// `normal` (world, unit) and `depth` (view depth in m; infinity on background).
pub fn write_exr(path: &Path, r: &Readback) -> Result<()> {
    let (w, h) = (r.width as usize, r.height as usize);
    let depth: Vec<f32> = r
        .position
        .iter()
        .map(|p| if p[3] > 0.0 { p[3] } else { f32::INFINITY })
        .collect();
    let layers = vec![
        rgb_layer("final", w, h, &r.final_radiance),
        rgb_layer("direct", w, h, &r.direct),
        rgb_layer("indirect", w, h, &r.indirect),
        rgb_layer("albedo", w, h, &r.albedo),
        rgb_layer("normal", w, h, &r.normal),
        Layer::new(
            (w, h),
            LayerAttributes::named("depth"),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
                "Z",
                FlatSamples::F32(depth),
            )])),
        ),
    ];
    let image = Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((w, h))),
        layers,
    );
    write_atomic(path, |out| {
        image.write().to_buffered(out).map_err(|e| anyhow!("{e}"))
    })
}

/// The tonemapped image (exposure, clamp, sRGB) as an 8-bit RGB PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<()> {
    let rgb: Vec<u8> = rgba8
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    write_atomic(path, |out| {
        image::write_buffer_with_format(
            out,
            &rgb,
            width,
            height,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(|e| anyhow!("{e}"))
    })
}

/// Tonemapped RGBA8 frames as a looping animated GIF at `fps` (each frame
/// quantised to its own 256-colour palette by the encoder).
pub fn write_gif(
    path: &Path,
    width: u32,
    height: u32,
    frames: Vec<Vec<u8>>,
    fps: f32,
) -> Result<()> {
    use image::codecs::gif::{GifEncoder, Repeat};
    // GIF delays are whole hundredths of a second.
    let delay = image::Delay::from_numer_denom_ms((1000.0 / fps).round().max(10.0) as u32, 1);
    write_atomic(path, |out| {
        let mut encoder = GifEncoder::new_with_speed(out, 10);
        encoder.set_repeat(Repeat::Infinite)?;
        for rgba in frames {
            let image = image::RgbaImage::from_raw(width, height, rgba)
                .ok_or_else(|| anyhow!("a frame does not have {width}x{height} pixels"))?;
            encoder.encode_frame(image::Frame::from_parts(image, 0, 0, delay))?;
        }
        Ok(())
    })
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
