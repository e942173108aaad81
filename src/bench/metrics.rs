//! Error measures of docs/algorithm.md section 6: relative RMSE (6.1) and
//! flicker (6.3), over the pixels with geometry. FLIP (6.4) is in `flip`.

/// Pixels with geometry: the G-buffer position's w (view depth) is positive.
pub fn geometry_mask(position: &[[f32; 4]]) -> Vec<bool> {
    position.iter().map(|p| p[3] > 0.0).collect()
}

/// Squared L2 norm of `a - b` (or of `a` when `b` is `None`) over the masked
/// pixels, all three channels.
fn sq_norm(a: &[[f32; 4]], b: Option<&[[f32; 4]]>, mask: &[bool]) -> f64 {
    let mut s = 0.0f64;
    for (i, x) in a.iter().enumerate() {
        if !mask[i] {
            continue;
        }
        for c in 0..3 {
            let d = x[c] as f64 - b.map_or(0.0, |b| b[i][c] as f64);
            s += d * d;
        }
    }
    s
}

/// `sqrt(sum (X - Ref)^2 / sum Ref^2)` over the masked pixels (section 6.1);
/// 0 when both are zero everywhere.
pub fn relative_rmse(x: &[[f32; 4]], reference: &[[f32; 4]], mask: &[bool]) -> f64 {
    let e = sq_norm(x, Some(reference), mask);
    let n = sq_norm(reference, None, mask);
    if n == 0.0 {
        if e == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    } else {
        (e / n).sqrt()
    }
}

/// The low-pass of flicker (section 6.3): a Gaussian whose standard
/// deviation is this fraction of the image's shorter side (8 pixels at
/// 128x128). Wide enough to average away the dense reference's own
/// texel-scale change near contact, narrow enough to keep a light patch's
/// jump on a wall.
pub const FLICKER_SIGMA: f64 = 1.0 / 16.0;

/// The flicker measure's name, for the journal's keys: rows measured with
/// another one are measured again.
pub const FLICKER_MEASURE: &str = "low-pass 1/16";

/// A normalised Gaussian of standard deviation `sigma` pixels, to 3 sigma.
fn gaussian(sigma: f64) -> Vec<f64> {
    let r = (3.0 * sigma).ceil() as i64;
    let k: Vec<f64> = (-r..=r)
        .map(|x| (-((x * x) as f64) / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f64 = k.iter().sum();
    k.into_iter().map(|v| v / sum).collect()
}

/// `x` (RGB per pixel) low-passed over the masked pixels only: the
/// Gaussian of `x * mask` over the Gaussian of `mask` (normalised
/// convolution), so that background and the image's border pull nothing
/// toward zero. Separable; zero where no masked pixel is near.
fn low_pass(x: &[[f64; 3]], mask: &[bool], w: usize, h: usize, kernel: &[f64]) -> Vec<[f64; 3]> {
    let r = (kernel.len() / 2) as i64;
    // Four planes: the three channels inside the mask (zero outside, so
    // that nothing there, not even a NaN, reaches the blur), and the mask.
    let planes: Vec<[f64; 4]> = x
        .iter()
        .zip(mask)
        .map(|(v, &m)| if m { [v[0], v[1], v[2], 1.0] } else { [0.0; 4] })
        .collect();
    let pass = |src: &[[f64; 4]], step: (i64, i64)| -> Vec<[f64; 4]> {
        let mut out = vec![[0.0; 4]; w * h];
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                let mut acc = [0.0; 4];
                for (i, k) in kernel.iter().enumerate() {
                    let o = i as i64 - r;
                    let (sx, sy) = (x + o * step.0, y + o * step.1);
                    if sx < 0 || sy < 0 || sx >= w as i64 || sy >= h as i64 {
                        continue;
                    }
                    let v = src[(sy * w as i64 + sx) as usize];
                    for c in 0..4 {
                        acc[c] += k * v[c];
                    }
                }
                out[(y * w as i64 + x) as usize] = acc;
            }
        }
        out
    };
    let blurred = pass(&pass(&planes, (1, 0)), (0, 1));
    blurred
        .iter()
        .map(|v| {
            if v[3] > 1e-12 {
                [v[0] / v[3], v[1] / v[3], v[2] / v[3]]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

/// Squared norm over the masked pixels of RGB `x`.
fn sq_norm3(x: &[[f64; 3]], mask: &[bool]) -> f64 {
    x.iter()
        .zip(mask)
        .filter(|(_, &m)| m)
        .map(|(v, _)| v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
        .sum()
}

/// Accumulates flicker (section 6.3) over a sequence, one frame at a time:
/// `RMS_t ||G * (E_t - E_{t-1})|| / RMS_t ||Ref_t||` with `E_t = I_t - Ref_t`
/// and `G` the low-pass ([`FLICKER_SIGMA`]); the second-difference variant
/// `G * (E_t - 2 E_{t-1} + E_{t-2})` (popping without smooth drift); and the
/// per-pixel first difference without `G` (the measure before the
/// low-pass, which on `fine` and `slats` the reference's own near-contact
/// change dominates for every method). Norms over the pixels with
/// geometry in frame `t`.
pub struct Flicker {
    width: usize,
    height: usize,
    kernel: Vec<f64>,
    /// The last two error images, newest last.
    errors: Vec<Vec<[f64; 3]>>,
    first: (f64, usize),
    second: (f64, usize),
    pixel: (f64, usize),
    reference: (f64, usize),
}

impl Flicker {
    /// For a sequence of `width x height` images.
    pub fn new(width: u32, height: u32) -> Self {
        let sigma = FLICKER_SIGMA * width.min(height) as f64;
        Flicker {
            width: width as usize,
            height: height as usize,
            kernel: gaussian(sigma.max(1e-3)),
            errors: vec![],
            first: (0.0, 0),
            second: (0.0, 0),
            pixel: (0.0, 0),
            reference: (0.0, 0),
        }
    }

    /// Adds frame `t`: the method's `image`, the `reference` and the mask,
    /// each of `width x height` pixels.
    pub fn add(
        &mut self,
        image: &[[f32; 4]],
        reference: &[[f32; 4]],
        mask: &[bool],
    ) -> anyhow::Result<()> {
        let n = self.width * self.height;
        anyhow::ensure!(
            image.len() == n && reference.len() == n && mask.len() == n,
            "flicker of {}x{} images given {}, {} and {} pixels",
            self.width,
            self.height,
            image.len(),
            reference.len(),
            mask.len()
        );
        let e: Vec<[f64; 3]> = image
            .iter()
            .zip(reference)
            .map(|(a, b)| [0, 1, 2].map(|c| a[c] as f64 - b[c] as f64))
            .collect();
        self.reference.0 += sq_norm(reference, None, mask);
        self.reference.1 += 1;
        let (w, h) = (self.width, self.height);
        if let Some(prev) = self.errors.last() {
            let d: Vec<[f64; 3]> = e
                .iter()
                .zip(prev)
                .map(|(a, b)| [0, 1, 2].map(|c| a[c] - b[c]))
                .collect();
            self.pixel.0 += sq_norm3(&d, mask);
            self.pixel.1 += 1;
            self.first.0 += sq_norm3(&low_pass(&d, mask, w, h, &self.kernel), mask);
            self.first.1 += 1;
        }
        if self.errors.len() == 2 {
            let d2: Vec<[f64; 3]> = (0..n)
                .map(|i| {
                    [0, 1, 2].map(|c| e[i][c] - 2.0 * self.errors[1][i][c] + self.errors[0][i][c])
                })
                .collect();
            self.second.0 += sq_norm3(&low_pass(&d2, mask, w, h, &self.kernel), mask);
            self.second.1 += 1;
            self.errors.remove(0);
        }
        self.errors.push(e);
        Ok(())
    }

    fn ratio(&self, (sum, n): (f64, usize)) -> Option<f64> {
        if n == 0 || self.reference.0 == 0.0 {
            return None;
        }
        let rms = (sum / n as f64).sqrt();
        let reference = (self.reference.0 / self.reference.1 as f64).sqrt();
        Some(rms / reference)
    }

    /// First-difference flicker, low-passed; `None` with fewer than two frames.
    pub fn flicker(&self) -> Option<f64> {
        self.ratio(self.first)
    }

    /// Second-difference flicker, low-passed; `None` with fewer than three frames.
    pub fn second_difference(&self) -> Option<f64> {
        self.ratio(self.second)
    }

    /// First-difference flicker per pixel, without the low-pass.
    pub fn per_pixel(&self) -> Option<f64> {
        self.ratio(self.pixel)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(v: f32) -> Vec<[f32; 4]> {
        vec![[v, v, v, 1.0]; 4]
    }

    #[test]
    fn relative_rmse_is_relative() {
        let mask = vec![true, true, true, false];
        assert_eq!(relative_rmse(&img(2.0), &img(2.0), &mask), 0.0);
        assert!((relative_rmse(&img(3.0), &img(2.0), &mask) - 0.5).abs() < 1e-12);
        // Masked pixels do not count.
        let mut x = img(2.0);
        x[3] = [100.0; 4];
        assert_eq!(relative_rmse(&x, &img(2.0), &mask), 0.0);
    }

    #[test]
    fn a_static_bias_does_not_flicker_but_popping_does() {
        let mask = vec![true; 4];
        let mut biased = Flicker::new(2, 2);
        let mut popping = Flicker::new(2, 2);
        for t in 0..4 {
            let r = img(1.0 + t as f32);
            biased.add(&img(1.5 + t as f32), &r, &mask).unwrap();
            let pop = if t % 2 == 0 { 0.5 } else { -0.5 };
            popping.add(&img(1.0 + t as f32 + pop), &r, &mask).unwrap();
        }
        assert_eq!(biased.flicker(), Some(0.0));
        assert_eq!(biased.second_difference(), Some(0.0));
        assert_eq!(biased.per_pixel(), Some(0.0));
        assert!(popping.flicker().unwrap() > 0.3);
        assert!(popping.second_difference().unwrap() > popping.flicker().unwrap());
        // A change alike over all pixels passes the low-pass whole.
        let (f, p) = (popping.flicker().unwrap(), popping.per_pixel().unwrap());
        assert!((f - p).abs() < 1e-9 * p, "{f} {p}");
        let mut one = Flicker::new(2, 2);
        one.add(&img(1.0), &img(1.0), &mask).unwrap();
        assert_eq!(one.flicker(), None);
        assert!(one.add(&img(1.0), &img(1.0), &mask[..3]).is_err());
    }

    /// A reference that changes texel by texel (a checker that flips every
    /// frame, what the dense reference's texel-sized VPLs do near contact)
    /// against a method that changes over a whole region at once (a light
    /// patch jumping): per pixel the two score alike, low-passed only the
    /// region's jump is left.
    #[test]
    fn the_low_pass_keeps_jumps_and_drops_texel_scale_change() {
        let (w, h) = (64usize, 64usize);
        let mask = vec![true; w * h];
        let base = 1.0f32;
        let mut speckle = Flicker::new(w as u32, h as u32);
        let mut jump = Flicker::new(w as u32, h as u32);
        for t in 0..4 {
            let checker: Vec<[f32; 4]> = (0..w * h)
                .map(|i| {
                    let odd = ((i % w) + (i / w) + t) % 2 == 1;
                    let v = base + if odd { 0.4 } else { -0.4 };
                    [v, v, v, 1.0]
                })
                .collect();
            let flat = vec![[base, base, base, 1.0]; w * h];
            // The method is smooth; the reference speckles.
            speckle.add(&flat, &checker, &mask).unwrap();
            // The reference is smooth; the method's left half jumps.
            let jumped: Vec<[f32; 4]> = (0..w * h)
                .map(|i| {
                    let v = base
                        + if i % w < w / 2 && t % 2 == 1 {
                            0.4
                        } else {
                            0.0
                        };
                    [v, v, v, 1.0]
                })
                .collect();
            jump.add(&jumped, &flat, &mask).unwrap();
        }
        let (s_pix, s_low) = (speckle.per_pixel().unwrap(), speckle.flicker().unwrap());
        let (j_pix, j_low) = (jump.per_pixel().unwrap(), jump.flicker().unwrap());
        // Per pixel the speckle even scores worse than the jump.
        assert!(s_pix > j_pix, "{s_pix} {j_pix}");
        assert!(s_low < 0.02 * s_pix, "{s_low} {s_pix}");
        assert!(j_low > 0.8 * j_pix, "{j_low} {j_pix}");
    }

    #[test]
    fn the_low_pass_stays_within_the_mask() {
        // A constant over masked pixels stays that constant: background
        // (zero, masked out) does not pull the edges down.
        let (w, h) = (16usize, 16usize);
        let mask: Vec<bool> = (0..w * h).map(|i| i % w >= 5).collect();
        let x: Vec<[f64; 3]> = (0..w * h)
            .map(|i| if mask[i] { [2.0, 3.0, 4.0] } else { [0.0; 3] })
            .collect();
        let y = low_pass(&x, &mask, w, h, &gaussian(3.0));
        for i in (0..w * h).filter(|&i| mask[i]) {
            for c in 0..3 {
                assert!((y[i][c] - x[i][c]).abs() < 1e-12, "{i} {:?}", y[i]);
            }
        }
    }
}
