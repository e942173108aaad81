//! Debug pictures computed on the host from read-back images.

use crate::readback::{MultiresReadback, Readback};

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

/// Linear value to an 8-bit sRGB code, clamped.
pub fn srgb(c: f32) -> u8 {
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

/// Light patches evaluated per eye-space patch: how many, over all patches.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LightPatchStats {
    /// Light patches the method's source chose this frame, for a source
    /// that chooses them anew every frame (Basic ISR's).
    pub chosen: Option<u32>,
    pub per_patch_min: u32,
    pub per_patch_mean: f64,
    pub per_patch_max: u32,
    /// Light-patch evaluations in the whole gather.
    pub total_evaluations: u64,
}

impl std::fmt::Display for LightPatchStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(c) = self.chosen {
            write!(f, "light patches chosen this frame: {c}; ")?;
        }
        write!(
            f,
            "light patches per eye-space patch: min {}, mean {:.1}, max {} ({} evaluations in all)",
            self.per_patch_min, self.per_patch_mean, self.per_patch_max, self.total_evaluations
        )
    }
}

/// Statistics of the evaluation counts over every patch of the buffer.
pub fn light_patch_stats(m: &MultiresReadback, chosen: Option<u32>) -> LightPatchStats {
    let mut counts = Vec::new();
    for l in 0..=m.levels as usize {
        for y in 0..m.height >> l {
            for x in 0..m.width >> l {
                let i = (y * m.width + x) as usize;
                if m.illumination[l][i][3] == 1.0 {
                    counts.push(m.evaluations[l][i]);
                }
            }
        }
    }
    let total: u64 = counts.iter().map(|&c| c as u64).sum();
    LightPatchStats {
        chosen,
        per_patch_min: counts.iter().copied().min().unwrap_or(0),
        per_patch_mean: total as f64 / counts.len().max(1) as f64,
        per_patch_max: counts.iter().copied().max().unwrap_or(0),
        total_evaluations: total,
    }
}

/// Heat map of the light patches evaluated for each pixel's patch (black, red,
/// yellow, white as the count rises from the image's minimum to its maximum;
/// dark blue: no patch), with that minimum and maximum.
pub fn vpl_count_png(m: &MultiresReadback) -> (Vec<u8>, u32, u32) {
    let w = m.width;
    let counts: Vec<Option<u32>> = patch_levels(m)
        .into_iter()
        .enumerate()
        .map(|(i, l)| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            l.map(|l| m.evaluations[l as usize][((y >> l) * w + (x >> l)) as usize])
        })
        .collect();
    let max = counts.iter().flatten().copied().max().unwrap_or(0);
    let min = counts.iter().flatten().copied().min().unwrap_or(0);
    let span = (max - min).max(1) as f32;
    let rgba = counts
        .iter()
        .flat_map(|c| match c {
            None => [0, 0, 64, 255],
            Some(c) => {
                let t = (*c - min) as f32 / span;
                let ramp = |a: f32| ((t * 3.0 - a).clamp(0.0, 1.0) * 255.0) as u8;
                [ramp(0.0), ramp(1.0), ramp(2.0), 255]
            }
        })
        .collect();
    (rgba, min, max)
}
