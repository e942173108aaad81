//! Host mirrors of HISR's structs and constants in `shaders/hisr/hisr.glsl`
//! (`tests/layouts.rs` checks them against the compiled SPIR-V and the
//! GLSL's text).

use bytemuck::{Pod, Zeroable};

/// Chained levels of HISR's tile cuts, as in `shaders/hisr/hisr.glsl`.
pub const HISR_CUT_LEVELS: usize = 3;

/// `HisrCutHeader` (std430): the head of HISR's per-tile cut buffer
/// (`shaders/hisr/cut.comp`): per level, tiles per row and column, tile level
/// and the offset of its counts; each level's entry offset (`entries[1 + c]`)
/// and its entries per tile (`capacity[c]`); the finest tiles' boxes at
/// `entries[0]` (8 floats a tile); with shared tile visibility, the
/// entries' corner visibilities at `visibility[0]`, `visibility[1]` words per
/// finest tile, and their march bits at `visibility[2]`, `visibility[3]`
/// words per finest tile, and the further tile points' pixels at
/// `points[0]` (4 words per finest tile), their visibilities at `points[1]`
/// and march bits at `points[2]`, laid out as the corners'
/// (`shaders/hisr/visibility.comp`); offsets in `u32`s after the header.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct HisrCutHeader {
    pub tiles: [[u32; 4]; HISR_CUT_LEVELS],
    pub entries: [u32; 4],
    pub capacity: [u32; 4],
    pub visibility: [u32; 4],
    pub points: [u32; 4],
}

/// A tile count that means "the cut did not fit", as in `shaders/hisr/hisr.glsl`.
pub const HISR_CUT_OVERFLOW: u32 = u32::MAX;

/// HISR splits an invalid patch while its bound could exceed tau times this,
/// as in `shaders/hisr/hisr.glsl`.
pub const HISR_INVALID_TAU_SCALE: f32 = 0.01;
