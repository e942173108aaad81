//! Multiple bounces for every gathering method (docs/algorithm.md section
//! 5.9, "Multiple bounces"; the shared notes' section 11): one mechanism,
//! naming no method, that adds bounces 2..N of `--bounces N` to whatever
//! indirect irradiance a method wrote. Its carrier is the voxel grid's
//! surface (`voxel_grid::surface`), so it reaches surfaces the light does
//! not see: the grid's finest cells are merged into [`SIDE`]^3 coarse cells,
//! each a piece of surface with an area, albedo, mean normal and centroid.
//! Every frame, per light view, nothing kept between frames:
//!
//! 1. `bounce-cells`: each cell's surface, and the first bounce's
//!    irradiance E at its centroid from [`VPLS`] regular VPLs of the RSM; it
//!    re-emits rho E A watts.
//! 2. `bounce-transfer`: the irradiance every cell gets per watt from every
//!    other (the patch formula with the run's visibility), once a frame.
//! 3. `bounce-propagate`: bounces 2..N-1 among the cells (`inf`: until a
//!    bounce brings under 1% of the power so far, at most [`INFINITE_CAP`]).
//! 4. `bounce-gather`: receivers at one pixel in [`STEP`] x [`STEP`] gather
//!    the cells' power summed over bounces 1..N-1, which is bounces 2..N at
//!    the receiver.
//! 5. `bounce-add`: upsampled (joint bilateral) and added to `indirect`.
//!
//! A method takes part through `Descriptor::renders_bounces`; with
//! `--bounces 1` none of these passes is made, so one bounce renders the
//! same commands as before.

mod passes;
pub use passes::BouncePass;

use crate::bounces::{Bounces, BOUNCES};
use crate::settings::RenderSettings;

/// Coarse cells per side of the grid's cube, as `shaders/bounce/bounce.glsl`.
pub const SIDE: u32 = 8;
/// Coarse cells in all.
pub const CELLS: u32 = SIDE * SIDE * SIDE;
/// Bytes per cell: three vec4s (`shaders/bounce/bounce.glsl`).
const CELL_BYTES: u64 = 48;
/// Receivers: one pixel per `STEP` x `STEP` block, upsampled.
pub const STEP: u32 = 4;
/// The regular VPLs each cell gathers its first bounce from (fewer where
/// the RSM has fewer texels).
pub const VPLS: u32 = 256;
/// The most bounces `--bounces inf` computes before it stops: where a room
/// keeps 0.9 of its light per bounce, the 1% test ends it near 40.
pub const INFINITE_CAP: u32 = 64;

/// How many times `bounce-propagate` runs for `s`: bounces 3..N need one
/// each (bounce 2 reaches receivers from the cells' first bounce); `None`
/// with one bounce, when no bounce pass runs.
pub fn propagations(s: &RenderSettings) -> Option<u32> {
    match BOUNCES.get(s) {
        Bounces::Count(n) if n <= 1 => None,
        Bounces::Count(n) => Some(n - 2),
        Bounces::Infinite => Some(INFINITE_CAP - 2),
    }
}

/// Whether `s` asks for more than one bounce.
pub fn active(s: &RenderSettings) -> bool {
    propagations(s).is_some()
}

/// Bytes of the buffers of the bounce passes for `s` (0 with one bounce):
/// the cells, three powers, the transfer between every pair of cells, and
/// the receivers.
pub fn memory(s: &RenderSettings) -> u64 {
    if !active(s) {
        return 0;
    }
    let cells = CELLS as u64;
    let receivers = (s.width.div_ceil(STEP) as u64) * (s.height.div_ceil(STEP) as u64);
    cells * CELL_BYTES + 3 * cells * 16 + cells * cells * 4 + receivers * 16 + 16
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn propagations_per_bounce_count() {
        let s = RenderSettings::DEFAULT;
        assert_eq!(propagations(&s), None);
        assert_eq!(memory(&s), 0);
        for (n, p) in [(2, 0), (3, 1), (8, 6)] {
            let s = RenderSettings::DEFAULT.with(&BOUNCES, Bounces::Count(n));
            assert_eq!(propagations(&s), Some(p));
        }
        let s = RenderSettings::DEFAULT.with(&BOUNCES, Bounces::Infinite);
        assert_eq!(propagations(&s), Some(INFINITE_CAP - 2));
        assert!(memory(&s) > (CELLS as u64).pow(2) * 4);
    }
}
