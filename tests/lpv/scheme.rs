//! The references `tests/lpv.rs` holds the GPU's grids to: an independent
//! f64 implementation of the propagation scheme (the paper's six-neighbour
//! face fluxes, docs/algorithm.md section 8.4) and a Lambertian point
//! emitter's irradiance. Apart from the tests because they are models, not
//! checks.

use super::probe::Vpl;
use glam::{DVec3, IVec3};
use isr::methods::lpv::grid::{self, Grid};
use isr::methods::lpv::Layout;

const FRONT: f64 = 0.400_669_684_646_239_2;
const SIDE: f64 = 0.423_431_354_436_738_96;

/// A cell's SH coefficients, per colour channel.
pub type Cell = [[f64; 4]; 3];

fn add(a: &mut [f64; 4], b: [f64; 4], s: f64) {
    for k in 0..4 {
        a[k] += s * b[k];
    }
}

/// `iterations` steps from `injected`, with blocking planes (light, eye)
/// when given; returns the sum over the steps, the injection included.
pub fn propagate_cpu(
    l: &Layout,
    injected: &Grid,
    blocking: Option<&[Vec<[f32; 4]>; 2]>,
) -> Vec<Cell> {
    let n = l.size as i32;
    let cells = l.cells() as usize;
    let index = |c: i32, p: IVec3| (((c * n + p.z) * n + p.y) * n + p.x) as usize;
    let mut step: Vec<Cell> = (0..cells)
        .map(|i| injected.planes.each_ref().map(|p| p[i].map(f64::from)))
        .collect();
    let mut sum = step.clone();
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    for _ in 0..l.iterations {
        let mut next = vec![[[0f64; 4]; 3]; cells];
        for c in 0..l.cascades as i32 {
            for z in 0..n {
                for y in 0..n {
                    for x in 0..n {
                        let cell = IVec3::new(x, y, z);
                        let corner = |i: i32| {
                            let k = (cell + IVec3::new(i & 1, (i >> 1) & 1, i >> 2))
                                .min(IVec3::splat(n - 1));
                            let j = index(c, k);
                            blocking.map(|b| [b[0][j].map(f64::from), b[1][j].map(f64::from)])
                        };
                        let mut out = [[0f64; 4]; 3];
                        for a in 0..3 {
                            for s in [1, -1] {
                                let mut d = IVec3::ZERO;
                                d[a] = s;
                                let from = cell - d;
                                if from.min_element() < 0 || from.max_element() >= n {
                                    continue;
                                }
                                let src = step[index(c, from)];
                                // The shared face's corners: offset 0 along a for d up the axis.
                                let mut bl = [0f64; 4];
                                let mut be = [0f64; 4];
                                for i in 0..8 {
                                    if ((i >> a) & 1) == (s < 0) as i32 {
                                        if let Some([l, e]) = corner(i) {
                                            add(&mut bl, l, 0.25);
                                            add(&mut be, e, 0.25);
                                        }
                                    }
                                }
                                let dir = d.as_dvec3();
                                let mut faces = vec![(dir, dir, FRONT)];
                                for b in 1..=2 {
                                    let e = axes[(a + b) % 3];
                                    for t in [1.0, -1.0] {
                                        faces.push(((dir + 0.5 * t * e).normalize(), t * e, SIDE));
                                    }
                                }
                                for (w, nf, omega) in faces {
                                    let mut t = omega / std::f64::consts::PI;
                                    if blocking.is_some() {
                                        let b = grid::sh_eval(bl, -w).max(grid::sh_eval(be, -w));
                                        t *= 1.0 - b.clamp(0.0, 1.0);
                                    }
                                    let lobe = grid::cosine_lobe(nf);
                                    for ch in 0..3 {
                                        let f = grid::sh_eval(src[ch], w).max(0.0) * t;
                                        add(&mut out[ch], lobe, f);
                                    }
                                }
                            }
                        }
                        next[index(c, cell)] = out;
                    }
                }
            }
        }
        for (s, v) in sum.iter_mut().zip(&next) {
            for ch in 0..3 {
                add(&mut s[ch], v[ch], 1.0);
            }
        }
        step = next;
    }
    sum
}

/// The largest difference between the GPU's sum and `cpu`, relative to the
/// largest coefficient.
pub fn worst_difference(gpu: &Grid, cpu: &[Cell]) -> f64 {
    let mut worst = 0f64;
    let mut peak = 0f64;
    for (i, cell) in cpu.iter().enumerate() {
        for (plane, sh) in gpu.planes.iter().zip(cell) {
            for (g, c) in plane[i].iter().zip(sh) {
                worst = worst.max((*g as f64 - c).abs());
                peak = peak.max(c.abs());
            }
        }
    }
    worst / peak
}

/// The irradiance a Lambertian point emitter gives (W/m^2 per W of flux).
pub fn analytic(vpl: &Vpl, p: DVec3, n: DVec3) -> f64 {
    let v = p - vpl.position.as_dvec3();
    let d2 = v.length_squared();
    let v = v / d2.sqrt();
    vpl.normal.as_dvec3().dot(v).max(0.0) * n.dot(-v).max(0.0) / (std::f64::consts::PI * d2)
}
