//! A short soak (the full one is `cargo bench --bench soak`): 300 frames with
//! the light and the camera moving. After warm-up the GPU allocator hands out
//! nothing more and resident memory stays flat: nothing leaks per frame.
mod common;

use common::*;
use isr::scene::cornell::cornell_box;

#[test]
fn memory_is_flat_over_300_moving_frames() {
    let gpu = gpu();
    let settings = sized("hisr", 32, 32, 64);
    let samples = isr::soak::run(&gpu, &cornell_box(), &settings, 300, 50, |_| {}).unwrap();
    assert_validation_clean(&gpu);
    let first = samples[0];
    for s in &samples {
        assert_eq!(
            (s.gpu_allocated, s.gpu_capacity, s.gpu_blocks),
            (first.gpu_allocated, first.gpu_capacity, first.gpu_blocks),
            "the GPU allocator's figures changed by frame {}",
            s.frame
        );
    }
    let at = |f: u32| samples.iter().find(|s| s.frame == f).unwrap().rss_kib;
    assert!(at(100) > 0, "no resident memory figure from /proc");
    // 2 MiB over 200 frames: a leak of 10 KiB per frame fails.
    let grown = at(300) as i64 - at(100) as i64;
    eprintln!(
        "resident memory: {} KiB at frame 100, {} KiB at 300",
        at(100),
        at(300)
    );
    assert!(
        grown < 2048,
        "resident memory grew by {grown} KiB from frame 100 to 300"
    );
}
