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

/// Accumulates flicker (section 6.3) over a sequence, one frame at a time:
/// `RMS_t ||E_t - E_{t-1}|| / RMS_t ||Ref_t||` with `E_t = I_t - Ref_t`, and
/// the second-difference variant `E_t - 2 E_{t-1} + E_{t-2}` (popping
/// without smooth drift). Norms over the pixels with geometry in frame `t`.
#[derive(Default)]
pub struct Flicker {
    /// The last two error images, newest last.
    errors: Vec<Vec<[f32; 4]>>,
    first: (f64, usize),
    second: (f64, usize),
    reference: (f64, usize),
}

impl Flicker {
    pub fn add(&mut self, image: &[[f32; 4]], reference: &[[f32; 4]], mask: &[bool]) {
        let e: Vec<[f32; 4]> = image
            .iter()
            .zip(reference)
            .map(|(a, b)| [a[0] - b[0], a[1] - b[1], a[2] - b[2], 0.0])
            .collect();
        self.reference.0 += sq_norm(reference, None, mask);
        self.reference.1 += 1;
        if let Some(prev) = self.errors.last() {
            self.first.0 += sq_norm(&e, Some(prev), mask);
            self.first.1 += 1;
        }
        if self.errors.len() == 2 {
            let d2: Vec<[f32; 4]> = (0..e.len())
                .map(|i| {
                    let f = |c: usize| e[i][c] - 2.0 * self.errors[1][i][c] + self.errors[0][i][c];
                    [f(0), f(1), f(2), 0.0]
                })
                .collect();
            self.second.0 += sq_norm(&d2, None, mask);
            self.second.1 += 1;
            self.errors.remove(0);
        }
        self.errors.push(e);
    }

    fn ratio(&self, (sum, n): (f64, usize)) -> Option<f64> {
        if n == 0 || self.reference.0 == 0.0 {
            return None;
        }
        let rms = (sum / n as f64).sqrt();
        let reference = (self.reference.0 / self.reference.1 as f64).sqrt();
        Some(rms / reference)
    }

    /// First-difference flicker; `None` with fewer than two frames.
    pub fn flicker(&self) -> Option<f64> {
        self.ratio(self.first)
    }

    /// Second-difference flicker; `None` with fewer than three frames.
    pub fn second_difference(&self) -> Option<f64> {
        self.ratio(self.second)
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
        let mut biased = Flicker::default();
        let mut popping = Flicker::default();
        for t in 0..4 {
            let r = img(1.0 + t as f32);
            biased.add(&img(1.5 + t as f32), &r, &mask);
            let pop = if t % 2 == 0 { 0.5 } else { -0.5 };
            popping.add(&img(1.0 + t as f32 + pop), &r, &mask);
        }
        assert_eq!(biased.flicker(), Some(0.0));
        assert_eq!(biased.second_difference(), Some(0.0));
        assert!(popping.flicker().unwrap() > 0.3);
        assert!(popping.second_difference().unwrap() > popping.flicker().unwrap());
        let mut one = Flicker::default();
        one.add(&img(1.0), &img(1.0), &mask);
        assert_eq!(one.flicker(), None);
    }
}
