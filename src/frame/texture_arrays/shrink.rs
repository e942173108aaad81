//! Shrinking a texture with a side over a layer's (`super::MAX_SIDE`): each
//! new texel is the mean of the old texels it covers, each weighted by the
//! share of it that it covers. Colour is averaged in linear light (a mean of
//! sRGB values darkens fine contrasty detail) and encoded back to sRGB;
//! alpha is averaged as it is.

use crate::scene::Texture;

/// `t` (whose pixels match its size) shrunk to `width` x `height`.
pub fn shrink(t: &Texture, width: u32, height: u32) -> Texture {
    let linear: Vec<f32> = (0..=255u8).map(srgb_to_linear).collect();
    let (taps_x, taps_y) = (taps(t.width, width), taps(t.height, height));
    let row_bytes = t.width as usize * 4;
    let mut rgba8 = Vec::with_capacity(width as usize * height as usize * 4);
    let mut row = vec![[0f32; 4]; width as usize];
    for ty in &taps_y {
        row.fill([0.0; 4]);
        for &(sy, wy) in ty {
            let src = &t.rgba8[sy * row_bytes..(sy + 1) * row_bytes];
            for (sum, tx) in row.iter_mut().zip(&taps_x) {
                for &(sx, wx) in tx {
                    let p = &src[sx * 4..sx * 4 + 4];
                    let w = wx * wy;
                    sum[0] += w * linear[p[0] as usize];
                    sum[1] += w * linear[p[1] as usize];
                    sum[2] += w * linear[p[2] as usize];
                    sum[3] += w * p[3] as f32 / 255.0;
                }
            }
        }
        for sum in &row {
            let alpha = (sum[3].clamp(0.0, 1.0) * 255.0).round() as u8;
            rgba8.extend([
                linear_to_srgb(sum[0]),
                linear_to_srgb(sum[1]),
                linear_to_srgb(sum[2]),
                alpha,
            ]);
        }
    }
    Texture {
        name: t.name.clone(),
        width,
        height,
        rgba8,
    }
}

/// Along one axis of `from` old texels shrunk to `to` new ones: for each new
/// texel, the old texels it covers and the share of it each covers (summing
/// to 1). New texel `i` covers old `[i * from / to, (i + 1) * from / to)`,
/// computed exactly in units of `1 / to` of an old texel.
fn taps(from: u32, to: u32) -> Vec<Vec<(usize, f32)>> {
    let (from, to) = (from as u64, to as u64);
    (0..to)
        .map(|i| {
            let (start, end) = (i * from, (i + 1) * from);
            (start / to..end.div_ceil(to))
                .map(|s| {
                    let covered = end.min((s + 1) * to) - start.max(s * to);
                    (s as usize, covered as f32 / from as f32)
                })
                .collect()
        })
        .collect()
}

/// The sRGB encoding of linear `c` (clamped to [0, 1]), rounded.
fn linear_to_srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let e = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taps_cover_each_new_texel_once() {
        for (from, to) in [(8, 4), (10, 4), (4097, 4096), (5, 1), (3, 3)] {
            let t = taps(from, to);
            assert_eq!(t.len(), to as usize);
            let mut per_old = vec![0f64; from as usize];
            for taps in &t {
                let sum: f32 = taps.iter().map(|&(_, w)| w).sum();
                assert!((sum - 1.0).abs() < 1e-5, "{from} -> {to}: {taps:?}");
                for &(s, w) in taps {
                    per_old[s] += w as f64;
                }
            }
            // Every old texel counts as much, `to / from` of a new one.
            for (s, &w) in per_old.iter().enumerate() {
                assert!(
                    (w - to as f64 / from as f64).abs() < 1e-5,
                    "{from} -> {to}: old {s}"
                );
            }
        }
    }

    #[test]
    fn shrinking_averages_in_linear_light() {
        // Columns alternating black and white, rows of opaque and clear:
        // each 2x2 block becomes linear 0.5 (sRGB 188), alpha 128.
        let (w, h) = (8, 2);
        let mut rgba8 = vec![];
        for y in 0..h {
            for x in 0..w {
                let c = if x % 2 == 0 { 0 } else { 255 };
                rgba8.extend([c, c, c, if y == 0 { 255 } else { 0 }]);
            }
        }
        let t = Texture {
            name: "stripes".into(),
            width: w,
            height: h,
            rgba8,
        };
        let s = shrink(&t, 4, 1);
        assert_eq!((s.width, s.height, s.rgba8.len()), (4, 1, 16));
        for px in s.rgba8.chunks_exact(4) {
            assert_eq!(px, [188, 188, 188, 128]);
        }
    }
}
