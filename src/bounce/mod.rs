//! Multiple bounces for every gathering method (docs/algorithm.md section
//! 5.9, "Multiple bounces"; the shared notes' section 11): one mechanism,
//! naming no method, that adds bounces 2..N of `--bounces N` to whatever
//! indirect irradiance a method wrote. Its carrier is the voxel grid's
//! surface (`voxel_grid::surface`), so it reaches surfaces the light does
//! not see: the grid's finest cells are merged into [`SIDE`]^3 coarse cells,
//! and each cell's surface split by facing into [`FACES`] faces, each a
//! piece of surface with an area, albedo, mean normal and centroid.
//! Every frame, per light view, nothing kept between frames:
//!
//! 1. `bounce-cells`: each cell's faces, and the first bounce's
//!    irradiance E at each face's centroid from [`VPLS`] regular VPLs of the
//!    RSM; a face re-emits rho E A watts.
//! 2. `bounce-transfer`: the visibility between every two cells (the run's
//!    visibility), once a frame; then `bounce-reach`, in the same timing
//!    scope: the scale on each face's power that keeps what the faces
//!    receive of it at most what it sends.
//! 3. `bounce-propagate`: bounces 2..N-1 among the faces (`inf`: until a
//!    bounce brings under 1% of the power so far, at most [`INFINITE_CAP`]).
//! 4. `bounce-gather`: receivers at one pixel in [`STEP`] x [`STEP`] gather
//!    the faces' power summed over bounces 1..N-1, which is bounces 2..N at
//!    the receiver.
//! 5. `bounce-add`: upsampled (joint bilateral) and added to `indirect`.
//!
//! A method takes part through `Descriptor::renders_bounces`; with
//! `--bounces 1` none of these passes is made, so one bounce renders the
//! same commands as before.
//!
//! With `--bounce-feedback on` (an ablation knob, `--bounces inf` only)
//! step 3 is `bounce-feedback` instead: one propagation from the power each
//! view's cells re-emitted over every bounce the frame before, kept per
//! view, so that the series is summed over frames; by default nothing is.

mod passes;
pub use passes::BouncePass;

use crate::bounces::{Bounces, BOUNCES};
use crate::settings::params::{DefaultValue, Param, ParamType as _, Range};
use crate::settings::RenderSettings;
use anyhow::{bail, Result};

/// `--bounce-feedback`: last frame's bounced light is this frame's source
/// (docs/algorithm.md section 5.9, "Temporal feedback").
pub const FEEDBACK: Param<bool> = Param {
    name: "bounce-feedback",
    help: "With --bounces inf: one propagation a frame from the cells' bounced power of the \
           frame before, which sums the series over frames (it lags when the light moves) \
           instead of up to 62 propagations in each; off: nothing is kept between frames",
    default: DefaultValue::Fixed(false),
    range: Range::ANY,
};

/// Whether `s` carries the cells' bounced power from frame to frame.
pub fn feedback(s: &RenderSettings) -> bool {
    FEEDBACK.get(s) && BOUNCES.get(s) == Bounces::Infinite
}

/// Refuses `--bounce-feedback on` without `--bounces inf`: the feedback
/// sums the whole series, so a count of bounces has no meaning with it.
pub fn check(s: &RenderSettings) -> Result<()> {
    if FEEDBACK.get(s) && BOUNCES.get(s) != Bounces::Infinite {
        bail!(
            "--bounce-feedback on with --bounces {}: the feedback sums every bounce over \
             frames; add --bounces inf, or leave --bounce-feedback off",
            BOUNCES.get(s).text()
        );
    }
    Ok(())
}

/// Coarse cells per side of the grid's cube, as `shaders/bounce/bounce.glsl`.
pub const SIDE: u32 = 8;
/// Coarse cells in all.
pub const CELLS: u32 = SIDE * SIDE * SIDE;
/// Faces per cell: its surface split by facing, one per axis direction
/// (`shaders/bounce/bounce.glsl`).
pub const FACES: u32 = 6;
/// vec4s per cell: one for the cell and three per face
/// (`shaders/bounce/bounce.glsl`, `BOUNCE_CELL_VEC4S`).
pub const CELL_VEC4S: u32 = 1 + 3 * FACES;
/// Bytes per cell.
const CELL_BYTES: u64 = 16 * CELL_VEC4S as u64;
/// Bytes of a power per face: a vec4 each.
const POWER_BYTES: u64 = CELLS as u64 * FACES as u64 * 16;
/// Bytes of the faces' reach (`bounce-reach`): a float each.
const REACH_BYTES: u64 = CELLS as u64 * FACES as u64 * 4;
/// Receivers: one pixel per `STEP` x `STEP` block, upsampled.
pub const STEP: u32 = 4;
/// The regular VPLs each cell gathers its first bounce from (fewer where
/// the RSM has fewer texels).
pub const VPLS: u32 = 1024;
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
        Bounces::Infinite if feedback(s) => Some(1),
        Bounces::Infinite => Some(INFINITE_CAP - 2),
    }
}

/// Whether `s` asks for more than one bounce.
pub fn active(s: &RenderSettings) -> bool {
    propagations(s).is_some()
}

/// Bytes of the buffers of the bounce passes for `s` (0 with one bounce):
/// the cells, three powers per face, the visibility between every pair of
/// cells, and
/// the receivers; with feedback a power per light view, counted for the
/// most views a frame renders (`MAX_LIGHT_VIEWS`: 512 KiB at most).
pub fn memory(s: &RenderSettings) -> u64 {
    if !active(s) {
        return 0;
    }
    let cells = CELLS as u64;
    let receivers = (s.width.div_ceil(STEP) as u64) * (s.height.div_ceil(STEP) as u64);
    let history = match feedback(s) {
        true => crate::frame::check::MAX_LIGHT_VIEWS as u64 * HISTORY_BYTES,
        false => 0,
    };
    cells * CELL_BYTES
        + 3 * POWER_BYTES
        + REACH_BYTES
        + cells * cells * 4
        + receivers * 16
        + 16
        + history
}

/// Bytes of one light view's kept power with feedback: a vec4 per face.
const HISTORY_BYTES: u64 = POWER_BYTES;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn propagations_per_bounce_count() {
        let s = RenderSettings::DEFAULT.with(&BOUNCES, Bounces::ONE);
        assert_eq!(propagations(&s), None);
        assert_eq!(memory(&s), 0);
        for (n, p) in [(2, 0), (3, 1), (8, 6)] {
            let s = RenderSettings::DEFAULT.with(&BOUNCES, Bounces::Count(n));
            assert_eq!(propagations(&s), Some(p));
        }
        let s = RenderSettings::DEFAULT.with(&BOUNCES, Bounces::Infinite);
        assert_eq!(propagations(&s), Some(INFINITE_CAP - 2));
        assert!(memory(&s) > (CELLS as u64).pow(2) * 4);
        let fed = s.clone().with(&FEEDBACK, true);
        assert_eq!(propagations(&fed), Some(1));
        assert_eq!(memory(&fed) - memory(&s), 64 * HISTORY_BYTES);
    }

    #[test]
    fn feedback_needs_every_bounce() {
        let s = RenderSettings::DEFAULT.with(&FEEDBACK, true);
        for n in [Bounces::ONE, Bounces::Count(3)] {
            let e = check(&s.clone().with(&BOUNCES, n)).unwrap_err().to_string();
            assert!(e.contains("add --bounces inf"), "{e}");
        }
        assert!(check(&s.with(&BOUNCES, Bounces::Infinite)).is_ok());
    }
}
