//! LDR FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild:
//! "FLIP: A Difference Evaluator for Alternating Images", HPG 2020), written
//! here from the paper's description for docs/algorithm.md section 6.4: the
//! perceptual difference of two tone-mapped (sRGB) images, per pixel in
//! [0, 1]. Not bit-exact with NVIDIA's reference code (borders are clamped;
//! filters are applied separably), but the same pipeline and constants:
//!
//! 1. Colour: sRGB -> linear -> XYZ -> YCxCz (opponent space); each channel
//!    filtered by its contrast-sensitivity function (a sum of Gaussians in
//!    degrees of visual angle); back to linear RGB clamped to [0, 1]; CIELAB
//!    with the Hunt adjustment (a, b scaled by 0.01 L); HyAB distance
//!    `|dL| + sqrt(da^2 + db^2)` raised to `Q_C`, then redistributed so that
//!    the distance between Hunt-adjusted green and blue maps to 1.
//! 2. Features: on the achromatic channel `Y / Y_w`, edges (first derivative
//!    of a Gaussian) and points (second derivative), of width `0.082` degrees;
//!    `dE_f = (max(|edge_a - edge_b|, |point_a - point_b|) / sqrt 2)^Q_F`.
//! 3. `FLIP = dE_c ^ (1 - dE_f)`.
//!
//! Viewing conditions: 67 pixels per degree (a 0.7 m wide 4K monitor seen
//! from 0.7 m), the paper's default.

/// The paper's default pixels per degree.
pub const PIXELS_PER_DEGREE: f64 = 67.0;
const Q_C: f64 = 0.7;
const Q_F: f64 = 0.5;
const P_C: f64 = 0.4;
const P_T: f64 = 0.95;
const FEATURE_WIDTH_DEG: f64 = 0.082;
/// D65 white in XYZ (linear sRGB (1, 1, 1)).
const WHITE: [f64; 3] = [0.950_47, 1.0, 1.088_83];

type Plane = Vec<f64>;

fn srgb_to_linear(c: u8) -> f64 {
    let c = c as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn rgb_to_xyz(c: [f64; 3]) -> [f64; 3] {
    [
        0.412_456_4 * c[0] + 0.357_576_1 * c[1] + 0.180_437_5 * c[2],
        0.212_672_9 * c[0] + 0.715_152_2 * c[1] + 0.072_175_0 * c[2],
        0.019_333_9 * c[0] + 0.119_192_0 * c[1] + 0.950_304_1 * c[2],
    ]
}

fn xyz_to_rgb(c: [f64; 3]) -> [f64; 3] {
    [
        3.240_454_2 * c[0] - 1.537_138_5 * c[1] - 0.498_531_4 * c[2],
        -0.969_266_0 * c[0] + 1.876_010_8 * c[1] + 0.041_556_0 * c[2],
        0.055_643_4 * c[0] - 0.204_025_9 * c[1] + 1.057_225_2 * c[2],
    ]
}

fn xyz_to_ycxcz(c: [f64; 3]) -> [f64; 3] {
    let (x, y, z) = (c[0] / WHITE[0], c[1] / WHITE[1], c[2] / WHITE[2]);
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

fn ycxcz_to_xyz(c: [f64; 3]) -> [f64; 3] {
    let y = (c[0] + 16.0) / 116.0;
    let x = c[1] / 500.0 + y;
    let z = y - c[2] / 200.0;
    [x * WHITE[0], y * WHITE[1], z * WHITE[2]]
}

/// CIELAB of linear RGB, Hunt-adjusted (a and b scaled by 0.01 L).
fn hunt_lab(rgb: [f64; 3]) -> [f64; 3] {
    let xyz = rgb_to_xyz(rgb);
    let f = |t: f64| {
        let d = 6.0 / 29.0;
        if t > d * d * d {
            t.cbrt()
        } else {
            t / (3.0 * d * d) + 4.0 / 29.0
        }
    };
    let (fx, fy, fz) = (
        f(xyz[0] / WHITE[0]),
        f(xyz[1] / WHITE[1]),
        f(xyz[2] / WHITE[2]),
    );
    let l = 116.0 * fy - 16.0;
    [
        l,
        0.01 * l * 500.0 * (fx - fy),
        0.01 * l * 200.0 * (fy - fz),
    ]
}

fn hyab(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).abs() + ((a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Convolves `p` (w x h) with `kx` along x then `ky` along y, both of odd
/// length centred on their middle, clamping at the borders.
fn separable(p: &[f64], w: usize, h: usize, kx: &[f64], ky: &[f64]) -> Plane {
    let (rx, ry) = ((kx.len() / 2) as isize, (ky.len() / 2) as isize);
    let mut tmp = vec![0.0; p.len()];
    for y in 0..h {
        for x in 0..w {
            let mut s = 0.0;
            for (k, wk) in kx.iter().enumerate() {
                let xx = (x as isize + k as isize - rx).clamp(0, w as isize - 1) as usize;
                s += wk * p[y * w + xx];
            }
            tmp[y * w + x] = s;
        }
    }
    let mut out = vec![0.0; p.len()];
    for y in 0..h {
        for x in 0..w {
            let mut s = 0.0;
            for (k, wk) in ky.iter().enumerate() {
                let yy = (y as isize + k as isize - ry).clamp(0, h as isize - 1) as usize;
                s += wk * tmp[yy * w + x];
            }
            out[y * w + x] = s;
        }
    }
    out
}

/// The contrast-sensitivity filter of one opponent channel: the sum of
/// Gaussians `a_k sqrt(pi / b_k) exp(-pi^2 d^2 / b_k)` (d in degrees),
/// normalised to sum 1 in 2D, applied one separable term at a time.
fn csf_filter(p: &[f64], w: usize, h: usize, terms: &[(f64, f64)], ppd: f64) -> Plane {
    let max_b: f64 = 0.04; // the widest term of all three channels
    let r = (3.0 * (max_b / (2.0 * std::f64::consts::PI.powi(2))).sqrt() * ppd).ceil() as isize;
    let pi2 = std::f64::consts::PI.powi(2);
    let gauss = |b: f64| -> Vec<f64> {
        (-r..=r)
            .map(|x| (-pi2 * (x as f64 / ppd).powi(2) / b).exp())
            .collect()
    };
    // 2D sum of all terms, for the normalisation.
    let total: f64 = terms
        .iter()
        .map(|&(a, b)| a * (std::f64::consts::PI / b).sqrt() * gauss(b).iter().sum::<f64>().powi(2))
        .sum();
    let mut out = vec![0.0; p.len()];
    for &(a, b) in terms {
        if a == 0.0 {
            continue;
        }
        let g = gauss(b);
        let scale = a * (std::f64::consts::PI / b).sqrt() / total;
        let gy: Vec<f64> = g.iter().map(|v| v * scale).collect();
        for (o, v) in out.iter_mut().zip(separable(p, w, h, &g, &gy)) {
            *o += v;
        }
    }
    out
}

/// Edge and point magnitudes of the achromatic plane (values in [0, 1]).
fn features(y: &[f64], w: usize, h: usize, ppd: f64) -> (Plane, Plane) {
    let sigma = 0.5 * FEATURE_WIDTH_DEG * ppd;
    let r = (3.0 * sigma).ceil() as isize;
    let xs: Vec<f64> = (-r..=r).map(|x| x as f64).collect();
    let g: Vec<f64> = xs
        .iter()
        .map(|x| (-x * x / (2.0 * sigma * sigma)).exp())
        .collect();
    let gsum: f64 = g.iter().sum();
    let smooth: Vec<f64> = g.iter().map(|v| v / gsum).collect();
    // Positive weights sum to 1 and negative ones to -1.
    let balance = |k: Vec<f64>| -> Vec<f64> {
        let pos: f64 = k.iter().filter(|v| **v > 0.0).sum();
        let neg: f64 = -k.iter().filter(|v| **v < 0.0).sum::<f64>();
        k.into_iter()
            .map(|v| if v > 0.0 { v / pos } else { v / neg.max(1e-30) })
            .collect()
    };
    let edge = balance(xs.iter().zip(&g).map(|(x, g)| -x * g).collect());
    let point = balance(
        xs.iter()
            .zip(&g)
            .map(|(x, g)| (x * x / (sigma * sigma) - 1.0) * g)
            .collect(),
    );
    let magnitude = |k: &[f64]| -> Plane {
        let gx = separable(y, w, h, k, &smooth);
        let gy = separable(y, w, h, &smooth, k);
        gx.iter().zip(&gy).map(|(a, b)| a.hypot(*b)).collect()
    };
    (magnitude(&edge), magnitude(&point))
}

/// Per-pixel FLIP of `test` against `reference`, both sRGB RGBA8 rows of
/// `width x height`.
pub fn flip_map(reference: &[u8], test: &[u8], width: u32, height: u32, ppd: f64) -> Vec<f32> {
    let (w, h) = (width as usize, height as usize);
    let n = w * h;
    struct Prepared {
        /// Filtered colour, Hunt-adjusted CIELAB.
        lab: Vec<[f64; 3]>,
        edge: Plane,
        point: Plane,
    }
    let prepare = |rgba: &[u8]| -> Prepared {
        let mut planes = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut achromatic = vec![0.0; n];
        for i in 0..n {
            let rgb = [0, 1, 2].map(|c| srgb_to_linear(rgba[4 * i + c]));
            let o = xyz_to_ycxcz(rgb_to_xyz(rgb));
            for c in 0..3 {
                planes[c][i] = o[c];
            }
            achromatic[i] = (o[0] + 16.0) / 116.0;
        }
        // Achromatic, red-green, blue-yellow CSFs: (a1, b1), (a2, b2).
        let csf: [&[(f64, f64)]; 3] = [
            &[(1.0, 0.0047), (0.0, 1e-5)],
            &[(1.0, 0.0053), (0.0, 1e-5)],
            &[(34.1, 0.04), (13.5, 0.025)],
        ];
        let filtered: Vec<Plane> = (0..3)
            .map(|c| csf_filter(&planes[c], w, h, csf[c], ppd))
            .collect();
        let lab = (0..n)
            .map(|i| {
                let xyz = ycxcz_to_xyz([filtered[0][i], filtered[1][i], filtered[2][i]]);
                hunt_lab(xyz_to_rgb(xyz).map(|v| v.clamp(0.0, 1.0)))
            })
            .collect();
        let (edge, point) = features(&achromatic, w, h, ppd);
        Prepared { lab, edge, point }
    };
    let (a, b) = (prepare(reference), prepare(test));
    let cmax = hyab(hunt_lab([0.0, 1.0, 0.0]), hunt_lab([0.0, 0.0, 1.0])).powf(Q_C);
    (0..n)
        .map(|i| {
            let d = hyab(a.lab[i], b.lab[i]).powf(Q_C);
            let color = if d < P_C * cmax {
                P_T / (P_C * cmax) * d
            } else {
                P_T + (d - P_C * cmax) / (cmax - P_C * cmax) * (1.0 - P_T)
            };
            let feature = ((a.edge[i] - b.edge[i])
                .abs()
                .max((a.point[i] - b.point[i]).abs())
                / std::f64::consts::SQRT_2)
                .powf(Q_F);
            color.powf(1.0 - feature) as f32
        })
        .collect()
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

    #[test]
    fn identical_images_differ_by_zero() {
        let a = flat(16, 16, [120, 30, 200]);
        let m = flip_map(&a, &a, 16, 16, PIXELS_PER_DEGREE);
        assert!(m.iter().all(|v| *v == 0.0));
    }

    #[test]
    fn green_against_blue_is_near_one_and_small_changes_are_small() {
        let g = flat(16, 16, [0, 255, 0]);
        let b = flat(16, 16, [0, 0, 255]);
        let m = flip_map(&g, &b, 16, 16, PIXELS_PER_DEGREE);
        assert!(m.iter().all(|v| (*v - 1.0).abs() < 0.02), "{}", m[0]);
        let grey = flat(16, 16, [128, 128, 128]);
        let grey2 = flat(16, 16, [132, 132, 132]);
        let black = flat(16, 16, [0, 0, 0]);
        let small = mean_flip(&flip_map(&grey, &grey2, 16, 16, 67.0), &[true; 256]);
        let large = mean_flip(&flip_map(&grey, &black, 16, 16, 67.0), &[true; 256]);
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
        let m = flip_map(&grey, &edge, w as u32, h as u32, 67.0);
        let at_edge = m[16 * w + w / 2];
        let away = m[16 * w + 2];
        assert!(at_edge > away, "edge {at_edge} away {away}");
    }
}
