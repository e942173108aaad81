//! The layout of HISR's cut buffer (`shaders/shared.glsl`, `HisrCutHeader`):
//! the tile cuts' counts and entries and, with shared visibility, the
//! tiles' corner and further points' visibilities and march bits; what
//! `CutPass` allocates and the method's memory states.

use super::{shares_visibility, SHARED_REFINE, TILE_LEVEL};
use crate::gpu_types::{HisrCutHeader, HISR_CUT_LEVELS};
use crate::settings::RenderSettings;

/// The most entries a tile's cut holds, per chained level (finest first). All
/// scale down together when there are so many tiles that the buffer would
/// pass `CUT_BUFFER_BUDGET` (above about 1600x1000). A tile whose cut does
/// not fit traverses from the roots: the same image without the grid,
/// slower; with it, its receivers march every patch instead of sharing the
/// tile's visibility. 2048 at every level: `slats` (up to 3,764 light patches
/// per eye patch at 256x256, RSM 256) overflowed 1024 at the two finer
/// levels and 1024 at the coarsest, and with the grid took 1.7x as long
/// (docs/algorithm.md section 5, "Tile-shared visibility").
const CUT_CAPACITY: [u64; HISR_CUT_LEVELS] = [2048, 2048, 2048];
const CUT_BUFFER_BUDGET: u64 = 64 << 20;

/// The cut buffer's header for `s` (`shaders/shared.glsl`): chained level c
/// has tiles of 2^(K + c) pixels a side; each level's counts, then each
/// level's entries, `capacity` per tile; with shared visibility, then a word
/// per finest tile and slot of every level and a bit per slot, and with
/// refinement the tile points' pixels and a word per slot for them (outside
/// the budget: 12.4 MiB at 256x256, 302 MiB at 1920x1080, stated in the
/// method's memory).
pub fn cut_layout(s: &RenderSettings) -> HisrCutHeader {
    let k = TILE_LEVEL.get(s);
    let mut header = HisrCutHeader::default();
    let mut tiles = [0u64; HISR_CUT_LEVELS];
    let mut offset = 0u64;
    for (c, level) in header.tiles.iter_mut().enumerate() {
        let side = 1u32 << (k + c as u32);
        let (tx, ty) = (s.width.div_ceil(side), s.height.div_ceil(side));
        tiles[c] = tx as u64 * ty as u64;
        *level = [tx, ty, k + c as u32, offset as u32];
        offset += tiles[c];
    }
    // The finest tiles' boxes (8 floats each).
    header.entries[0] = offset as u32;
    offset += 8 * tiles[0];
    let full: u64 = (0..HISR_CUT_LEVELS)
        .map(|c| tiles[c] * CUT_CAPACITY[c])
        .sum();
    // Entries over the budget: scale every level's capacity down alike.
    let scale = (CUT_BUFFER_BUDGET as f64 / 4.0 / full as f64).min(1.0);
    for c in 0..HISR_CUT_LEVELS {
        let capacity = ((CUT_CAPACITY[c] as f64 * scale) as u64).max(64);
        header.capacity[c] = capacity as u32;
        header.entries[1 + c] = offset as u32;
        offset += tiles[c] * capacity;
    }
    // The entries' corner visibilities: per finest tile, one word per slot
    // of every level; then a bit per slot, set where the receivers march the
    // entry themselves (the gather's loops skip by words of these bits).
    if shares_visibility(s) {
        let slots: u32 = header.capacity[..3].iter().sum();
        let words = offset + tiles[0] * slots as u64;
        header.visibility = [offset as u32, slots, words as u32, slots.div_ceil(32)];
        // With refinement, up to 4 more points per tile where the corners
        // leave receivers uncovered (4 words), their visibilities (a word
        // per slot, as the corners') and the march bits of the receivers
        // that take them.
        if SHARED_REFINE.get(s) < 1.0 {
            let pixels = words + tiles[0] * slots.div_ceil(32) as u64;
            let points = pixels + 4 * tiles[0];
            let point_bits = points + tiles[0] * slots as u64;
            header.points = [pixels as u32, points as u32, point_bits as u32, 0];
        }
    }
    header
}

/// Bytes of the cut buffer (0 without tiles).
pub fn cut_bytes(s: &RenderSettings) -> u64 {
    if TILE_LEVEL.get(s) == 0 {
        return 0;
    }
    let header = cut_layout(s);
    let entries: u64 = (0..HISR_CUT_LEVELS)
        .map(|c| {
            let t = header.tiles[c];
            t[0] as u64 * t[1] as u64 * (1 + header.capacity[c] as u64)
        })
        .sum();
    let [tx, ty, ..] = header.tiles[0];
    let boxes = 8 * tx as u64 * ty as u64;
    let mut per_tile = (header.visibility[1] + header.visibility[3]) as u64;
    if header.points[1] != 0 {
        per_tile += 4 + (header.visibility[1] + header.visibility[3]) as u64;
    }
    let visibility = per_tile * tx as u64 * ty as u64;
    std::mem::size_of::<HisrCutHeader>() as u64 + 4 * (entries + boxes + visibility)
}
