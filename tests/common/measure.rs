//! Work done on this thread, to bound what a call does instead of timing it:
//! bytes it had allocated at its peak (through [`Counting`], which a test
//! binary installs as its global allocator) and bytes it read from files.
//! Per thread, so tests running beside it do not count.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting each thread's live bytes and their peak.
/// Install it in a test binary with
/// `#[global_allocator] static ALLOC: common::measure::Counting = common::measure::Counting;`.
pub struct Counting;

thread_local! {
    // Const-initialised cells without destructors: reading them allocates
    // nothing, so the allocator may use them.
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

fn grew(bytes: usize) {
    let _ = LIVE.try_with(|live| {
        let now = live.get() + bytes as isize;
        live.set(now);
        let _ = PEAK.try_with(|p| p.set(p.get().max(now)));
    });
}

fn shrank(bytes: usize) {
    let _ = LIVE.try_with(|live| live.set(live.get() - bytes as isize));
}

// SAFETY: every call is passed on to `System` unchanged; the counting only
// touches this thread's cells.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            grew(l.size());
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        shrank(l.size());
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, l, new) };
        if !q.is_null() {
            shrank(l.size());
            grew(new);
        }
        q
    }
}

/// Runs `f` and returns, with its result, the most bytes it had allocated
/// on this thread at once beyond what was live when it began (0 unless
/// [`Counting`] is the global allocator).
pub fn peak_allocated<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(base));
    let out = f();
    let peak = PEAK.with(Cell::get);
    (out, (peak - base).max(0) as usize)
}

/// Bytes this thread has read through `read` system calls (Linux:
/// `rchar` of /proc/thread-self/io).
pub fn thread_bytes_read() -> u64 {
    let io = std::fs::read_to_string("/proc/thread-self/io")
        .expect("/proc/thread-self/io (Linux) counts the bytes a thread reads");
    io.lines()
        .find_map(|l| l.strip_prefix("rchar:"))
        .and_then(|n| n.trim().parse().ok())
        .expect("rchar in /proc/thread-self/io")
}

/// Runs `f` and returns, with its result, the bytes it read on this thread.
pub fn bytes_read<T>(f: impl FnOnce() -> T) -> (T, u64) {
    let before = thread_bytes_read();
    let out = f();
    // The difference includes one read of /proc/thread-self/io (about
    // 100 bytes).
    (out, thread_bytes_read() - before)
}
