//! SIGINT, SIGTERM and SIGHUP: the temporaries of unfinished writes are
//! removed (`output::abandon_temporaries`, which also keeps new ones from
//! being made), a line says what was left, and the process ends as the
//! signal would have ended it (so a shell sees it interrupted). Finished
//! files are whole either way: they are renamed into place complete.
//!
//! signal-hook turns the signal into a message to a thread of ours, where
//! files can be removed (a signal handler itself may do almost nothing). A
//! signal this process inherited as ignored (a background job of a script)
//! stays ignored.

use crate::output;
use anyhow::{Context as _, Result};
use std::sync::Mutex;

/// What a run has finished so far, for the line printed on an interruption
/// ("frames 0000 to 0004 in seq are complete; ...").
static NOTE: Mutex<Option<String>> = Mutex::new(None);

/// Sets the note printed if the run is interrupted.
pub(super) fn set_note(note: impl Into<String>) {
    *NOTE.lock().unwrap_or_else(|e| e.into_inner()) = Some(note.into());
}

fn name(signal: i32) -> &'static str {
    match signal {
        signal_hook::consts::SIGINT => "SIGINT",
        signal_hook::consts::SIGTERM => "SIGTERM",
        signal_hook::consts::SIGHUP => "SIGHUP",
        _ => "a signal",
    }
}

/// Whether `signal` was inherited as ignored.
fn ignored(signal: i32) -> bool {
    // SAFETY: with a null new action, sigaction only reads the current one
    // into `old`, a zeroed plain C struct.
    unsafe {
        let mut old: libc::sigaction = std::mem::zeroed();
        libc::sigaction(signal, std::ptr::null(), &mut old) == 0
            && old.sa_sigaction == libc::SIG_IGN
    }
}

/// Installs the handling; call once, before any output is written.
pub(super) fn install() -> Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let wanted: Vec<i32> = [SIGINT, SIGTERM, SIGHUP]
        .into_iter()
        .filter(|&s| !ignored(s))
        .collect();
    let mut signals =
        signal_hook::iterator::Signals::new(&wanted).context("installing signal handlers")?;
    std::thread::Builder::new()
        .name("isr-signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let removed = output::abandon_temporaries();
                let note = NOTE.lock().unwrap_or_else(|e| e.into_inner()).clone();
                let removed = match removed {
                    0 => "no unfinished file was left".to_string(),
                    1 => "removed the temporary file of an unfinished write".to_string(),
                    n => format!("removed the temporary files of {n} unfinished writes"),
                };
                eprintln!(
                    "\nisr: interrupted by {}; {removed}{}",
                    name(signal),
                    note.map(|n| format!("; {n}")).unwrap_or_default()
                );
                // Ends the process as the signal's default action does.
                let _ = signal_hook::low_level::emulate_default_handler(signal);
                signal_hook::low_level::exit(128 + signal);
            }
        })
        .context("starting the signal thread")?;
    Ok(())
}
