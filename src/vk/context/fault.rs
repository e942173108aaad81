//! A test hook for the failures a real GPU can hit in the middle of a run and
//! lavapipe never does: `ISR_INJECT_FAULT=device-lost:N` (or
//! `out-of-memory:N`) makes the N-th queue submission (1-based) fail with
//! `VK_ERROR_DEVICE_LOST` (or `VK_ERROR_OUT_OF_DEVICE_MEMORY`) instead of
//! reaching the driver, so tests can check what the user sees then.

use anyhow::{bail, Result};
use ash::vk;
use std::sync::atomic::{AtomicU64, Ordering};

pub const ENV: &str = "ISR_INJECT_FAULT";

pub struct InjectedFault {
    error: vk::Result,
    /// Submissions left before the failing one.
    countdown: AtomicU64,
}

impl InjectedFault {
    /// The fault the environment asks for, if any.
    pub fn from_env() -> Result<Option<Self>> {
        match std::env::var(ENV) {
            Ok(v) => Self::parse(&v).map(Some),
            Err(_) => Ok(None),
        }
    }

    fn parse(v: &str) -> Result<Self> {
        let parsed = v.split_once(':').and_then(|(kind, n)| {
            let error = match kind {
                "device-lost" => vk::Result::ERROR_DEVICE_LOST,
                "out-of-memory" => vk::Result::ERROR_OUT_OF_DEVICE_MEMORY,
                _ => return None,
            };
            let n: u64 = n.parse().ok().filter(|&n| n >= 1)?;
            Some(Self {
                error,
                countdown: AtomicU64::new(n - 1),
            })
        });
        match parsed {
            Some(f) => Ok(f),
            None => bail!(
                "{ENV}={v}: expected device-lost:N or out-of-memory:N with N >= 1 \
                 (a test hook; unset it for normal runs)"
            ),
        }
    }

    /// Counts one submission; the error it must fail with, if it is the one.
    pub fn on_submit(&self) -> Option<vk::Result> {
        let left = self
            .countdown
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| n.checked_sub(1))
            .ok();
        // Only the submission that finds the countdown at 0 fails; later ones
        // run (the caller stops at the first error anyway).
        if left.is_none() && self.countdown.swap(u64::MAX, Ordering::SeqCst) == 0 {
            return Some(self.error);
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nth_submission_fails_once() {
        let f = InjectedFault::parse("device-lost:3").unwrap();
        let seen: Vec<_> = (0..5).map(|_| f.on_submit()).collect();
        assert_eq!(
            seen,
            [None, None, Some(vk::Result::ERROR_DEVICE_LOST), None, None]
        );
        let f = InjectedFault::parse("out-of-memory:1").unwrap();
        assert_eq!(f.on_submit(), Some(vk::Result::ERROR_OUT_OF_DEVICE_MEMORY));
        for bad in ["device-lost", "device-lost:0", "melt:2", "out-of-memory:x"] {
            let e = InjectedFault::parse(bad).err().unwrap().to_string();
            assert!(e.contains("expected device-lost:N"), "{bad}: {e}");
        }
    }
}
