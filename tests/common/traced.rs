//! The path tracer at one sample a pixel and one bounce: what a test holds
//! the rasterised direct light (exact and noise-free in the path tracer,
//! by next-event estimation to a punctual light), the G-buffer's albedo or
//! the first bounce's positions to.

use isr::readback::Readback;
use isr::scene::Scene;

/// `scene` path traced at `width` x `height`, one sample, seed 1.
pub fn traced_once(scene: &Scene, width: u32, height: u32) -> Readback {
    isr::pathtrace::render(
        scene,
        &isr::pathtrace::PathTraceSettings {
            width,
            height,
            spp: 1,
            seed: 1,
            exposure: 1.0,
            bounces: isr::bounces::Bounces::ONE,
        },
        |_, _| {},
    )
}
