//! The layout of HISR's cut buffer (`shaders/hisr/hisr.glsl`, `HisrCutHeader`):
//! the tile cuts' counts and entries and, with shared visibility, the
//! tiles' corner and further points' visibilities and march bits; what
//! `CutPass` allocates and the method's memory states.

use super::gpu::{HisrCutHeader, HISR_CUT_LEVELS};
use super::{shares_visibility, SHARED_REFINE, TILE_LEVEL};
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

/// The most bytes the cut buffer may take with the visibility words: 2^27,
/// the least `maxStorageBufferRange` a Vulkan device may have, so that one
/// descriptor binds it on every device. Past it (shared visibility from
/// about 760x760 on), every capacity scales down further.
const CUT_BUFFER_LIMIT: u64 = 1 << 27;

/// The cut buffer's header for `s` (`shaders/hisr/hisr.glsl`): chained level c
/// has tiles of 2^(K + c) pixels a side; each level's counts, then each
/// level's entries, `capacity` per tile; with shared visibility, then a word
/// per finest tile and slot of every level and a bit per slot, and with
/// refinement the tile points' pixels and a word per slot for them (outside
/// the entries' budget, within `CUT_BUFFER_LIMIT`: 12.4 MiB at 256x256,
/// stated in the method's memory).
pub fn cut_layout(s: &RenderSettings) -> HisrCutHeader {
    let tiles = tiles(s);
    let full: u64 = (0..HISR_CUT_LEVELS)
        .map(|c| tiles[c] * CUT_CAPACITY[c])
        .sum();
    // Entries over the budget: scale every level's capacity down alike.
    let mut scale = (CUT_BUFFER_BUDGET as f64 / 4.0 / full as f64).min(1.0);
    let mut header = layout_at(s, scale);
    // Then the whole buffer over the limit: shrink by the ratio until it
    // fits (the part that does not scale, the counts and boxes, is small,
    // so a few rounds do).
    for _ in 0..16 {
        let bytes = header_bytes(&header);
        if bytes <= CUT_BUFFER_LIMIT {
            break;
        }
        scale *= CUT_BUFFER_LIMIT as f64 / bytes as f64;
        header = layout_at(s, scale);
    }
    header
}

/// Tiles across and down of each chained level of `s`.
fn tile_counts(s: &RenderSettings) -> [[u32; 2]; HISR_CUT_LEVELS] {
    let k = TILE_LEVEL.get(s);
    std::array::from_fn(|c| {
        let side = 1u32 << (k + c as u32);
        [s.width.div_ceil(side), s.height.div_ceil(side)]
    })
}

/// Tiles of each chained level of `s`.
fn tiles(s: &RenderSettings) -> [u64; HISR_CUT_LEVELS] {
    tile_counts(s).map(|[tx, ty]| tx as u64 * ty as u64)
}

/// The layout of `s` with every level's capacity `CUT_CAPACITY` times
/// `scale` (at least 64).
fn layout_at(s: &RenderSettings, scale: f64) -> HisrCutHeader {
    let k = TILE_LEVEL.get(s);
    let mut header = HisrCutHeader::default();
    let tiles = tiles(s);
    let mut offset = 0u64;
    for (c, (level, [tx, ty])) in header.tiles.iter_mut().zip(tile_counts(s)).enumerate() {
        *level = [tx, ty, k + c as u32, offset as u32];
        offset += tiles[c];
    }
    // The finest tiles' boxes (8 floats each).
    header.entries[0] = offset as u32;
    offset += 8 * tiles[0];
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
    header_bytes(&cut_layout(s))
}

/// Bytes of the cut buffer `header` lays out.
fn header_bytes(header: &HisrCutHeader) -> u64 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::Method;
    use crate::visibility::{Visibility, VISIBILITY};

    fn hisr(width: u32, height: u32, grid: bool) -> RenderSettings {
        let mut s = RenderSettings {
            width,
            height,
            method: Method::new("hisr"),
            ..Default::default()
        };
        let v = if grid {
            Visibility::Voxels
        } else {
            Visibility::None
        };
        VISIBILITY.set(&mut s, v);
        s
    }

    /// Within the least `maxStorageBufferRange` a device may have at every
    /// size, with shared visibility or without; the capacities stay whole at
    /// the bench's sizes, and shrink no more than the limit needs.
    #[test]
    fn the_cut_buffer_fits_one_descriptor_on_every_device() {
        for (w, h) in [
            (128, 128),
            (256, 256),
            (1024, 768),
            (1920, 1080),
            (3840, 2160),
        ] {
            for grid in [false, true] {
                let s = hisr(w, h, grid);
                let header = cut_layout(&s);
                let bytes = cut_bytes(&s);
                assert!(bytes <= CUT_BUFFER_LIMIT, "{w}x{h} {grid}: {bytes}");
                assert_eq!(shares_visibility(&s), grid);
                if w <= 256 {
                    assert_eq!(header.capacity[..3], [2048; 3], "{w}x{h} {grid}");
                } else if grid {
                    // Two more entries per level would not fit.
                    let c = header.capacity[0] as f64;
                    let more = layout_at(&s, (c + 2.5) / 2048.0);
                    assert!(header_bytes(&more) > CUT_BUFFER_LIMIT, "{w}x{h}: {c}");
                }
            }
        }
    }
}
