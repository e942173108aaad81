//! Debug pictures computed on the host from read-back images.

use crate::renderer::{MultiresReadback, Readback};

/// Colors of levels 0, 1, 2, ... (cycled past the end).
const PALETTE: [[u8; 3]; 8] = [
    [230, 25, 75],
    [245, 130, 48],
    [255, 225, 25],
    [60, 180, 75],
    [70, 240, 240],
    [0, 130, 200],
    [145, 30, 180],
    [240, 50, 230],
];

pub const LEVEL_LEGEND: &str =
    "0 red, 1 orange, 2 yellow, 3 green, 4 cyan, 5 blue, 6 purple, 7 magenta; black: no patch";

/// Level of the patch covering each pixel (`None` for background), from the
/// illumination buffer's "is a patch" alpha.
pub fn patch_levels(m: &MultiresReadback) -> Vec<Option<u32>> {
    let (w, h) = (m.width, m.height);
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            (0..=m.levels)
                .find(|&l| m.illumination[l as usize][((y >> l) * w + (x >> l)) as usize][3] == 1.0)
        })
        .collect()
}

/// RGBA8 image coloring each pixel by its patch's level.
pub fn levels_png(m: &MultiresReadback) -> Vec<u8> {
    patch_levels(m)
        .into_iter()
        .flat_map(|l| match l {
            Some(l) => {
                let c = PALETTE[l as usize % PALETTE.len()];
                [c[0], c[1], c[2], 255]
            }
            None => [0, 0, 0, 255],
        })
        .collect()
}

fn srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let e = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0 + 0.5) as u8
}

/// RGBA8 image of the indirect radiance alone, albedo/pi * E, times `exposure`.
pub fn indirect_png(r: &Readback, exposure: f32) -> Vec<u8> {
    r.indirect
        .iter()
        .zip(&r.albedo)
        .flat_map(|(e, a)| {
            let c = |k: usize| srgb(a[k] / std::f32::consts::PI * e[k] * exposure);
            [c(0), c(1), c(2), 255]
        })
        .collect()
}
