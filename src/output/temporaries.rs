//! The temporaries behind every atomic write: their names
//! (`.NAME.PID-N.tmp`, shortened with a hash of NAME where that would pass
//! the file system's name limit), the list of this process's live ones (so
//! that an interruption can remove them, [`abandon_temporaries`]), and the
//! sweep of those a dead process left in a folder. Apart from the checks and
//! the writes in `output`, because this is the state they share: a lock, a
//! counter and the set of folders already swept.

use super::{folder, name_max};
use anyhow::{anyhow, Result};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

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
pub(super) fn forget_temporary(tmp: &Path, remove: bool) {
    let mut live = lock(&LIVE);
    if remove {
        let _ = std::fs::remove_file(tmp);
    }
    live.retain(|p| p != tmp);
}

/// Whether `e` says a file name was too long.
pub(super) fn name_too_long(e: &anyhow::Error) -> bool {
    e.chain()
        .filter_map(|c| c.downcast_ref::<std::io::Error>())
        .any(|e| e.kind() == std::io::ErrorKind::InvalidFilename)
}

/// A new file next to `path` (same folder, so the rename cannot cross file
/// systems), created exclusively so it never clobbers anything, and listed
/// as live. The folder's stale temporaries are removed first.
pub(super) fn temp_file(path: &Path) -> Result<(PathBuf, std::fs::File)> {
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
