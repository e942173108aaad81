//! The one runner of the built `isr` binary. A run is killed after
//! `HANG_GUARD` (a hang fails its test instead of the whole suite: a guard,
//! never what a test asserts), its output is captured, and on Linux its
//! peak resident memory is read from the kernel (`wait4`), so a test can
//! bound the work a run did rather than the time it took.

use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// Longer than any run of the suite takes on a loaded machine.
pub const HANG_GUARD: Duration = Duration::from_secs(300);

/// `isr` and its arguments, before it runs.
pub struct Isr {
    cmd: Command,
    line: Vec<String>,
    guard: Duration,
}

/// A run in progress ([`Isr::spawn`]): signal it, then wait for it.
pub struct Running {
    child: std::process::Child,
    stdout: std::thread::JoinHandle<String>,
    stderr: std::thread::JoinHandle<String>,
    started: Instant,
    guard: Duration,
    line: String,
}

/// What one run did.
pub struct Ran {
    pub status: ExitStatus,
    pub stdout: String,
    pub stderr: String,
    /// Peak resident memory of the process (KiB), where the platform says.
    pub peak_kib: Option<u64>,
    /// The command line, for messages.
    pub line: String,
}

impl Isr {
    /// `isr SUBCOMMAND`, in the current folder.
    pub fn new(subcommand: &str) -> Isr {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_isr"));
        cmd.arg(subcommand);
        Isr {
            cmd,
            line: vec![subcommand.into()],
            guard: HANG_GUARD,
        }
    }

    /// `isr render` run in `dir`: relative paths, and the default outputs,
    /// are there.
    pub fn render(dir: &Path) -> Isr {
        Isr::new("render").in_dir(dir)
    }

    /// `isr render` of one small frame (32x32, RSM 32) in `dir`.
    pub fn tiny(dir: &Path) -> Isr {
        Isr::render(dir).args([
            "--frames", "1", "--width", "32", "--height", "32", "--rsm", "32",
        ])
    }

    pub fn arg(mut self, a: impl AsRef<OsStr>) -> Isr {
        self.line.push(a.as_ref().to_string_lossy().into_owned());
        self.cmd.arg(a);
        self
    }

    pub fn args<A: AsRef<OsStr>>(self, args: impl IntoIterator<Item = A>) -> Isr {
        args.into_iter().fold(self, Isr::arg)
    }

    pub fn in_dir(mut self, dir: &Path) -> Isr {
        self.cmd.current_dir(dir);
        self
    }

    pub fn env(mut self, key: &str, value: impl AsRef<OsStr>) -> Isr {
        self.cmd.env(key, value);
        self
    }

    pub fn env_remove(mut self, key: &str) -> Isr {
        self.cmd.env_remove(key);
        self
    }

    /// Kills the run after `guard` instead of [`HANG_GUARD`] (a run that
    /// should end in seconds but might hang: a guard, still not asserted).
    pub fn hang_guard(mut self, guard: Duration) -> Isr {
        self.guard = guard;
        self
    }

    /// The child starts with SIGINT, SIGTERM and SIGHUP at their default
    /// actions, whatever this process inherited: a test run started in the
    /// background of a shell has SIGINT ignored, which isr rightly keeps
    /// (`cli::interrupt`), so a test of isr's own handling sets them.
    #[cfg(unix)]
    pub fn default_signals(mut self) -> Isr {
        use std::os::unix::process::CommandExt as _;
        // SAFETY: the closure only calls signal(), which is
        // async-signal-safe, as pre_exec requires.
        unsafe {
            self.cmd.pre_exec(|| {
                for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
                    libc::signal(s, libc::SIG_DFL);
                }
                Ok(())
            });
        }
        self
    }

    /// Runs to the end (or to the hang guard, which fails the test).
    pub fn run(self) -> Ran {
        self.spawn().wait()
    }

    /// Starts the run and returns at once.
    pub fn spawn(mut self) -> Running {
        let line = self.line.join(" ");
        let mut child = self
            .cmd
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the isr binary runs");
        let read = |mut r: Box<dyn std::io::Read + Send>| {
            std::thread::spawn(move || {
                let mut s = Vec::new();
                let _ = r.read_to_end(&mut s);
                String::from_utf8_lossy(&s).into_owned()
            })
        };
        let stdout = read(Box::new(child.stdout.take().unwrap()));
        let stderr = read(Box::new(child.stderr.take().unwrap()));
        Running {
            child,
            stdout,
            stderr,
            started: Instant::now(),
            guard: self.guard,
            line,
        }
    }

    /// Runs and expects success.
    pub fn succeeds(self) -> Ran {
        let ran = self.run();
        assert!(
            ran.status.success(),
            "isr {} failed:\n{}",
            ran.line,
            ran.stderr
        );
        ran
    }

    /// Runs and expects a clean failure ([`Ran::clean_failure`]); returns stderr.
    pub fn fails(self) -> String {
        self.run().clean_failure()
    }
}

impl Running {
    /// Whether the run has ended (it is not reaped: [`Running::wait`] still
    /// returns its status).
    pub fn has_ended(&self) -> bool {
        // SAFETY: waitid with WNOWAIT only reads the child's state.
        #[cfg(target_os = "linux")]
        unsafe {
            let mut info: libc::siginfo_t = std::mem::zeroed();
            let r = libc::waitid(
                libc::P_PID,
                self.child.id(),
                &mut info,
                libc::WEXITED | libc::WNOHANG | libc::WNOWAIT,
            );
            r == 0 && info.si_pid() != 0
        }
        #[cfg(not(target_os = "linux"))]
        false
    }

    /// Sends signal `signal` (`libc::SIGINT`, ...) to the run.
    #[cfg(unix)]
    pub fn signal(&self, signal: i32) {
        // SAFETY: kill has no memory effects; the child is not yet reaped,
        // so its PID is still its own.
        let r = unsafe { libc::kill(self.child.id() as i32, signal) };
        assert_eq!(r, 0, "kill: {}", std::io::Error::last_os_error());
    }

    /// Waits for the end (or the hang guard, which fails the test).
    pub fn wait(mut self) -> Ran {
        let line = self.line;
        let (status, peak_kib) = loop {
            if let Some(done) = reap(&mut self.child) {
                break done;
            }
            if self.started.elapsed() > self.guard {
                let _ = self.child.kill();
                let _ = reap_blocking(&mut self.child);
                panic!("isr {line} hung: killed after {:?}", self.guard);
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        Ran {
            status,
            stdout: self.stdout.join().unwrap(),
            stderr: self.stderr.join().unwrap(),
            peak_kib,
            line,
        }
    }
}

impl Ran {
    /// Expects a failure with an `error:` message, exit status 1 (or clap's
    /// 2 for a usage error; not a panic's 101, not a signal) and nothing of
    /// a file's contents (of /etc/passwd, which hostile URIs name) in it;
    /// returns stderr.
    pub fn clean_failure(self) -> String {
        let e = self.stderr;
        let line = &self.line;
        assert!(!self.status.success(), "expected isr {line} to fail:\n{e}");
        assert!(
            !e.contains("panicked") && !e.contains("RUST_BACKTRACE"),
            "isr {line} panicked:\n{e}"
        );
        assert!(
            matches!(self.status.code(), Some(1 | 2)),
            "isr {line} ended with {}:\n{e}",
            self.status
        );
        assert!(e.contains("error:"), "isr {line}: no error message:\n{e}");
        assert!(
            !e.contains("root:"),
            "isr {line}: file contents leaked:\n{e}"
        );
        println!("isr {line}:\n{e}");
        e
    }
}

#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
mod sys {
    /// `struct rusage` on 64-bit Linux: two `timeval`s, then 14 longs, the
    /// first being `ru_maxrss` (KiB).
    #[repr(C)]
    pub struct Rusage {
        pub times: [i64; 4],
        pub maxrss: i64,
        pub rest: [i64; 13],
    }
    extern "C" {
        pub fn wait4(pid: i32, status: *mut i32, options: i32, usage: *mut Rusage) -> i32;
    }
    pub const WNOHANG: i32 = 1;
}

/// The exit status and peak memory of `child` if it has ended (reaping it).
#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
fn reap(child: &mut std::process::Child) -> Option<(ExitStatus, Option<u64>)> {
    wait(child, sys::WNOHANG)
}

#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
fn reap_blocking(child: &mut std::process::Child) -> Option<(ExitStatus, Option<u64>)> {
    wait(child, 0)
}

#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
fn wait(child: &mut std::process::Child, options: i32) -> Option<(ExitStatus, Option<u64>)> {
    use std::os::unix::process::ExitStatusExt as _;
    let pid = child.id() as i32;
    let mut status = 0;
    let mut usage = std::mem::MaybeUninit::<sys::Rusage>::zeroed();
    loop {
        // SAFETY: `pid` is our child, not yet reaped (std's `Child` is
        // never waited on here); both pointers are to live locals.
        let r = unsafe { sys::wait4(pid, &mut status, options, usage.as_mut_ptr()) };
        if r == pid {
            // SAFETY: zero-initialised, then filled by the kernel.
            let usage = unsafe { usage.assume_init() };
            return Some((ExitStatus::from_raw(status), Some(usage.maxrss as u64)));
        }
        if r == 0 {
            return None;
        }
        let err = std::io::Error::last_os_error();
        assert_eq!(
            err.kind(),
            std::io::ErrorKind::Interrupted,
            "wait4 on isr: {err}"
        );
    }
}

#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
fn reap(child: &mut std::process::Child) -> Option<(ExitStatus, Option<u64>)> {
    child.try_wait().unwrap().map(|s| (s, None))
}

#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
fn reap_blocking(child: &mut std::process::Child) -> Option<(ExitStatus, Option<u64>)> {
    child.wait().ok().map(|s| (s, None))
}
