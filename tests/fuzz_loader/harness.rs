//! What the stable fuzz tests share: running one input under a panic
//! guard, a time limit and an allocation limit; a watchdog that keeps the
//! input of a load that hangs; the regressions folder, whose inputs are
//! replayed first and where failing ones are kept.

use crate::common::measure::peak_allocated;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering::Relaxed};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// More than `Limits::FUZZ` can account for (a few copies of 8 MiB of
/// buffers or of a file, 32k vertices, 256k texels).
pub const MAX_PEAK: usize = 96 << 20;
/// One load taking this long is a hang (they take well under 10 ms): a
/// guard, 300 times a load's time, like the watchdog's 30 s abort.
pub const SLOW: Duration = Duration::from_secs(3);

static PANIC_MESSAGE: Mutex<String> = Mutex::new(String::new());
/// The input being loaded (its extension and bytes), for the watchdog.
static CURRENT: Mutex<Option<(String, Vec<u8>)>> = Mutex::new(None);
/// When it started (ms since `EPOCH`), `u64::MAX` between loads.
static STARTED_MS: AtomicU64 = AtomicU64::new(u64::MAX);
static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();

/// Installs the panic hook (panics inside a load are recorded with their
/// input; the test's own assertions print as usual) and the watchdog, once;
/// returns when the test began.
pub fn start() -> Instant {
    static STARTED: AtomicBool = AtomicBool::new(false);
    let epoch = *EPOCH.get_or_init(Instant::now);
    if STARTED.swap(true, Relaxed) {
        return epoch;
    }
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if STARTED_MS.load(Relaxed) == u64::MAX {
            return default(info);
        }
        if let Ok(mut m) = PANIC_MESSAGE.lock() {
            *m = info.to_string();
        }
    }));
    // A hang inside the loader cannot be interrupted from the test's own
    // thread: the watchdog keeps the input and aborts.
    std::thread::spawn(move || loop {
        std::thread::sleep(Duration::from_millis(200));
        let since = STARTED_MS.load(Relaxed);
        if since == u64::MAX {
            continue;
        }
        let now = epoch.elapsed().as_millis() as u64;
        if now.saturating_sub(since) > 30_000 {
            if let Some((ext, bytes)) = CURRENT.lock().ok().and_then(|c| c.clone()) {
                let p = save(&ext, &bytes, "hang: a load ran for more than 30 s");
                eprintln!("fuzz: a load hangs; input kept as {}", p.display());
            }
            std::process::abort();
        }
    });
    epoch
}

pub fn regressions_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz-regressions")
}

/// Keeps a failing input (as `HASH.ext`, its problem beside it).
pub fn save(ext: &str, bytes: &[u8], problem: &str) -> PathBuf {
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    });
    let dir = regressions_dir();
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("{hash:016x}.{ext}"));
    std::fs::write(&p, bytes).unwrap();
    std::fs::write(p.with_extension(format!("{ext}.txt")), problem).unwrap();
    p
}

/// The inputs kept in the regressions folder with one of `exts`, in order.
pub fn regressions(exts: &[&str]) -> Vec<(String, Vec<u8>, PathBuf)> {
    let Ok(entries) = std::fs::read_dir(regressions_dir()) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
    files.sort();
    files
        .into_iter()
        .filter_map(|p| {
            let ext = p.extension()?.to_str()?.to_string();
            exts.contains(&ext.as_str())
                .then(|| (ext, std::fs::read(&p).unwrap(), p))
        })
        .collect()
}

/// Runs one input (`ext` and `bytes`, to keep it if it fails): `load`
/// returns `Ok(None)` for a scene that passed its checks, `Ok(Some(e))`
/// for the loader's error `e` (that passed them), `Err(problem)` when the
/// input broke a property. A panic, a load over [`SLOW`] or an allocation
/// peak over [`MAX_PEAK`] is a problem too. Returns the outcome, or `None`
/// with the failure added to `failures` (and the input kept when `keep`).
pub fn run(
    ext: &str,
    bytes: &[u8],
    keep: bool,
    failures: &mut Vec<String>,
    load: impl FnOnce() -> Result<Option<String>, String>,
) -> Option<Option<String>> {
    let epoch = start();
    *CURRENT.lock().unwrap() = Some((ext.to_string(), bytes.to_vec()));
    let started = Instant::now();
    STARTED_MS.store(epoch.elapsed().as_millis() as u64, Relaxed);
    let (result, peak) =
        peak_allocated(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(load)));
    STARTED_MS.store(u64::MAX, Relaxed);
    let took = started.elapsed();
    let problem = match &result {
        Err(_) => Some(format!(
            "panic: {}",
            PANIC_MESSAGE.lock().map(|m| m.clone()).unwrap_or_default()
        )),
        Ok(Err(p)) => Some(p.clone()),
        Ok(Ok(_)) if took > SLOW => Some(format!("took {took:?}")),
        Ok(Ok(_)) if peak > MAX_PEAK => Some(format!("allocated {} MiB at peak", peak >> 20)),
        Ok(Ok(_)) => None,
    };
    match (problem, result) {
        (None, Ok(Ok(outcome))) => Some(outcome),
        (problem, _) => {
            let p = problem.unwrap_or_default();
            let kept = if keep {
                format!(" (kept as {})", save(ext, bytes, &p).display())
            } else {
                String::new()
            };
            failures.push(format!(".{ext}{kept}: {p}"));
            None
        }
    }
}

/// The loader's error without the file's path, cut before details, to
/// count the common ones.
pub fn message_key(e: &str) -> String {
    let e = e.split(": ").skip(1).take(2).collect::<Vec<_>>().join(": ");
    e.chars().take(60).collect()
}
