//! Writing results: a multi-layer OpenEXR of linear data and a PNG for viewing.
//!
//! Every file is written to a temporary name in its own folder, flushed to
//! disk and renamed over the final path, so an interrupted or failed write
//! never leaves a truncated file where a good one was. [`check_outputs`]
//! checks the paths before any rendering, so bad ones fail in a second rather
//! than after the render.
//!
//! An output that is a symbolic link is written through: the new file
//! replaces the link's target, and the link stays ([`resolve_links`]).
//! Temporaries are named `.NAME.PID-N.tmp` (shortened with a hash of NAME
//! where that would pass the file system's name limit); this process's live
//! ones are listed, so that an interruption can remove them
//! ([`abandon_temporaries`]), and those a dead process left in a folder are
//! removed the first time this process writes there.

use crate::readback::Readback;
use anyhow::{anyhow, bail, Context as _, Result};
use exr::prelude::*;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

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

/// The extensions of what `isr` writes: a temporary `.NAME.PID-N.tmp` whose
/// NAME ends in one of them is of this program's pattern.
const OWN_EXTENSIONS: &[&str] = &["exr", "png", "json", "gif", "csv", "md", "svg", "gltf"];

/// The temporary's name for file `name` (extension `ext`): `.NAME.PID-N.tmp`,
/// or where that is longer than `max` bytes, NAME cut short (at a character)
/// and followed by a hash of the whole name and its extension,
/// `.NAM~HASH.EXT.PID-N.tmp`, within `max`.
fn temp_name(name: &str, ext: &str, pid: u32, n: u32, max: usize) -> String {
    let plain = format!(".{name}.{pid}-{n}.tmp");
    if plain.len() <= max {
        return plain;
    }
    // FNV-1a: stable across runs and Rust versions, enough to tell names apart
    // (the PID and counter make the temporary unique anyway).
    let hash = name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    });
    let tail = format!("~{hash:016x}.{ext}.{pid}-{n}.tmp");
    let mut cut = max.saturating_sub(1 + tail.len()).min(name.len());
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    format!(".{}{tail}", &name[..cut])
}

/// The PID in `name` if it is a temporary of this program's pattern.
fn temporary_pid(name: &str) -> Option<u32> {
    let inner = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (file, id) = inner.rsplit_once('.')?;
    let (pid, n) = id.split_once('-')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !digits(pid) || !digits(n) {
        return None;
    }
    let (_, ext) = file.rsplit_once('.')?;
    if !OWN_EXTENSIONS.iter().any(|e| e.eq_ignore_ascii_case(ext)) {
        return None;
    }
    pid.parse().ok()
}

/// Whether process `pid` may be alive (when in doubt, it is).
fn pid_alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = i32::try_from(pid) else {
            return true;
        };
        if pid <= 0 {
            return true;
        }
        // SAFETY: signal 0 only asks whether the process exists.
        if unsafe { libc::kill(pid, 0) } == 0 {
            return true;
        }
        // EPERM: it exists, as another user's.
        std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// Removes, once per process and folder, the temporaries of this program's
/// pattern in `dir` whose process is not alive: what a run that could not
/// clean up (SIGKILL, a crash, a power cut) left. Each one is named on stderr.
fn sweep_stale(dir: &Path) {
    static SWEPT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    let Ok(key) = std::fs::canonicalize(dir) else {
        return;
    };
    {
        let mut swept = lock(&SWEPT);
        if swept.contains(&key) {
            return;
        }
        swept.push(key);
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(temporary_pid) else {
            continue;
        };
        if pid == std::process::id() || pid_alive(pid) {
            continue;
        }
        if entry.file_type().is_ok_and(|t| t.is_file())
            && std::fs::remove_file(entry.path()).is_ok()
        {
            eprintln!(
                "removed {}, a temporary file left by an interrupted run (process {pid})",
                entry.path().display()
            );
        }
    }
}

/// This process's temporaries not yet renamed or removed. A temporary is
/// created with this lock held, so once [`abandon_temporaries`] holds it,
/// none can appear.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary of this process and keeps any more from being
/// created (the lock is never released): for a process about to end on a
/// signal. Returns how many were removed.
pub fn abandon_temporaries() -> usize {
    let live = lock(&LIVE);
    let removed = live
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count();
    std::mem::forget(live);
    removed
}

/// Takes `tmp` off the live list (renamed into place, or removed first
/// when `remove`).
fn forget_temporary(tmp: &Path, remove: bool) {
    let mut live = lock(&LIVE);
    if remove {
        let _ = std::fs::remove_file(tmp);
    }
    live.retain(|p| p != tmp);
}

/// Whether `e` says a file name was too long.
fn name_too_long(e: &anyhow::Error) -> bool {
    e.chain()
        .filter_map(|c| c.downcast_ref::<std::io::Error>())
        .any(|e| e.kind() == std::io::ErrorKind::InvalidFilename)
}

/// A new file next to `path` (same folder, so the rename cannot cross file
/// systems), created exclusively so it never clobbers anything, and listed
/// as live. The folder's stale temporaries are removed first.
fn temp_file(path: &Path) -> Result<(PathBuf, std::fs::File)> {
    static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let dir = folder(path);
    sweep_stale(&dir);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| anyhow!("{} does not name a file", path.display()))?;
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let max = name_max(&dir);
    loop {
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp_name = temp_name(&name, ext, std::process::id(), n, max);
        let tmp = dir.join(&tmp_name);
        let mut live = lock(&LIVE);
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(f) => {
                live.push(tmp.clone());
                return Ok((tmp, f));
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) if e.kind() == std::io::ErrorKind::InvalidFilename => {
                return Err(anyhow::Error::new(e).context(format!(
                    "the temporary file name {tmp_name} ({} bytes) is too long for the file \
                     system of {}",
                    tmp_name.len(),
                    dir.display()
                )))
            }
            Err(e) => {
                return Err(anyhow::Error::new(e)
                    .context(format!("cannot create a file in {}", dir.display())))
            }
        }
    }
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
