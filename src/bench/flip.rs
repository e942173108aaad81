//! LDR FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild:
//! "FLIP: A Difference Evaluator for Alternating Images", HPG 2020) for
//! docs/algorithm.md section 6.4: the perceptual difference of two
//! tone-mapped (sRGB) images, per pixel in [0, 1], computed by the authors'
//! own C++ (NVIDIA's reference implementation, through the `nv-flip` crate)
//! rather than by a reading of the paper, so that the bench's numbers are
//! the ones NVIDIA's tool gives.

use anyhow::{ensure, Result};

/// The paper's default viewing conditions: 67 pixels per degree (a 0.7 m
/// wide 4K monitor seen from 0.7 m).
pub const PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// sRGB RGB8 of an RGBA8 image (FLIP has no alpha).
fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Per-pixel FLIP of `test` against `reference`, both sRGB RGBA8 rows of
/// `width x height`. Images of another size than `width x height` are an
/// error (the crate asserts on short ones, and would read only part of
/// long ones).
pub fn flip_map(
    reference: &[u8],
    test: &[u8],
    width: u32,
    height: u32,
    ppd: f32,
) -> Result<Vec<f32>> {
    let n = width as usize * height as usize;
    ensure!(
        width > 0 && height > 0,
        "FLIP of an empty image ({width}x{height})"
    );
    for (what, img) in [("reference", reference), ("test", test)] {
        ensure!(
            img.len() == 4 * n,
            "FLIP: the {what} image has {} bytes, not the {} of {width}x{height} RGBA8",
            img.len(),
            4 * n
        );
    }
    ensure!(
        ppd.is_finite() && ppd > 0.0,
        "FLIP: pixels per degree must be positive (got {ppd})"
    );
    let image = |rgba: &[u8]| nv_flip::FlipImageRgb8::with_data(width, height, &rgb(rgba));
    Ok(nv_flip::flip(image(reference), image(test), ppd).to_vec())
}

/// Mean FLIP over the pixels where `mask` is true (all pixels if none are).
pub fn mean_flip(map: &[f32], mask: &[bool]) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for (v, m) in map.iter().zip(mask) {
        if *m {
            s += *v as f64;
            n += 1;
        }
    }
    if n == 0 {
        map.iter().map(|v| *v as f64).sum::<f64>() / map.len().max(1) as f64
    } else {
        s / n as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(w: usize, h: usize, rgb: [u8; 3]) -> Vec<u8> {
        (0..w * h)
            .flat_map(|_| [rgb[0], rgb[1], rgb[2], 255])
            .collect()
    }

    fn map(a: &[u8], b: &[u8], w: usize, h: usize) -> Vec<f32> {
        flip_map(a, b, w as u32, h as u32, PIXELS_PER_DEGREE).unwrap()
    }

    #[test]
    fn identical_images_differ_by_zero() {
        let a = flat(16, 16, [120, 30, 200]);
        assert!(map(&a, &a, 16, 16).iter().all(|v| *v == 0.0));
    }

    #[test]
    fn green_against_blue_is_near_one_and_small_changes_are_small() {
        let g = flat(16, 16, [0, 255, 0]);
        let b = flat(16, 16, [0, 0, 255]);
        let m = map(&g, &b, 16, 16);
        assert!(m.iter().all(|v| (*v - 1.0).abs() < 0.02), "{}", m[0]);
        let grey = flat(16, 16, [128, 128, 128]);
        let grey2 = flat(16, 16, [132, 132, 132]);
        let black = flat(16, 16, [0, 0, 0]);
        let small = mean_flip(&map(&grey, &grey2, 16, 16), &[true; 256]);
        let large = mean_flip(&map(&grey, &black, 16, 16), &[true; 256]);
        assert!(small > 0.0 && small < 0.1, "{small}");
        assert!(large > 0.5 && large <= 1.0, "{large}");
    }

    #[test]
    fn an_edge_adds_feature_error() {
        // The same mean colour, but a sharp edge in one image only.
        let (w, h) = (32, 32);
        let grey = flat(w, h, [128, 128, 128]);
        let edge: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                let v = if i % w < w / 2 { 100 } else { 156 };
                [v, v, v, 255]
            })
            .collect();
        let m = map(&grey, &edge, w, h);
        let at_edge = m[16 * w + w / 2];
        let away = m[16 * w + 2];
        assert!(at_edge > away, "edge {at_edge} away {away}");
    }

    #[test]
    fn images_of_the_wrong_size_are_errors() {
        let a = flat(16, 16, [10, 20, 30]);
        let short = flat(16, 15, [10, 20, 30]);
        for (r, t) in [(&a, &short), (&short, &a)] {
            let e = flip_map(r, t, 16, 16, PIXELS_PER_DEGREE).unwrap_err();
            assert!(e.to_string().contains("not the 1024"), "{e}");
        }
        assert!(flip_map(&[], &[], 0, 4, PIXELS_PER_DEGREE).is_err());
        assert!(flip_map(&a, &a, 16, 16, 0.0).is_err());
    }
}
