//! The host's copy of what `shaders/lpv/lpv.glsl` and `shaders/lpv/lookup.frag`
//! compute (docs/algorithm.md section 8): where the cascades are, the 2-band
//! SH, and the irradiance a point reads from a cascade. Tests read the GPU's
//! grids back into a [`Grid`] and compare.

use super::Layout;
use crate::gpu_types::FrameUniforms;
use glam::{DVec3, IVec3, Vec3};

/// SH basis constants (`shaders/lpv/lpv.glsl`): `Y0`, `Y1`, the clamped
/// cosine's projection and the integral of an SH function per unit `c0`.
pub const SH_Y0: f64 = 0.282_094_791_773_878_14;
pub const SH_Y1: f64 = 0.488_602_511_902_919_9;
pub const SH_COS0: f64 = 0.886_226_925_452_758;
pub const SH_COS1: f64 = 1.023_326_707_946_488_5;
pub const SH_FLUX: f64 = 3.544_907_701_811_031_8;

/// `f(w)` for SH coefficients `(c0, cx, cy, cz)`.
pub fn sh_eval(f: [f64; 4], w: DVec3) -> f64 {
    f[0] * SH_Y0 + SH_Y1 * (f[1] * w.x + f[2] * w.y + f[3] * w.z)
}

/// `max(0, n.w)` projected.
pub fn cosine_lobe(n: DVec3) -> [f64; 4] {
    [SH_COS0, SH_COS1 * n.x, SH_COS1 * n.y, SH_COS1 * n.z]
}

/// One cascade's place this frame (`lpv_cell_size`, `lpv_origin`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cascade {
    /// Cell side (m).
    pub cell: f32,
    /// Its first cell, in whole cells from the render origin.
    pub origin: IVec3,
}

impl Cascade {
    /// Point `p` in cell coordinates (cell `i` spans `[i, i + 1)`).
    pub fn grid_position(&self, p: DVec3) -> DVec3 {
        p / self.cell as f64 - self.origin.as_dvec3()
    }

    /// The world position of cell coordinates `g`.
    pub fn world(&self, g: DVec3) -> DVec3 {
        (g + self.origin.as_dvec3()) * self.cell as f64
    }
}

/// The cascades of a frame with uniforms `u`, finest first, computed in f32
/// as the shaders do.
pub fn cascades(u: &FrameUniforms, layout: &Layout) -> Vec<Cascade> {
    let n = layout.size as f32;
    let reach = 32768.0 / u.normal_depth_scale;
    (0..layout.cascades as i32)
        .map(|c| {
            let h = reach * 2f32.powi(c - (layout.cascades as i32 - 1)) / n;
            let camera = Vec3::from(u.camera_position);
            let forward = Vec3::from(u.camera_forward);
            let centre = camera + forward * (0.375 * n * h);
            let origin = (centre / h).floor().as_ivec3() - IVec3::splat(layout.size as i32 / 2);
            Cascade { cell: h, origin }
        })
        .collect()
}

/// SH vectors per cell of every cascade, per colour channel, in the GPU's
/// cell order (`lpv_cell_index`).
pub struct Grid {
    pub layout: Layout,
    /// `[red, green, blue]`, each `Layout::cells` SH vectors.
    pub planes: [Vec<[f32; 4]>; 3],
}

impl Grid {
    /// From the bytes of an SH buffer (three planes, `Lpv::sum`).
    pub fn from_planes(layout: Layout, bytes: &[u8]) -> Self {
        let all: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(bytes);
        let n = layout.cells() as usize;
        assert!(all.len() >= 3 * n, "an SH buffer of {} cells", all.len());
        Self {
            layout,
            planes: [0, 1, 2].map(|i| all[i * n..(i + 1) * n].to_vec()),
        }
    }

    /// From the three injection images' layers, in layer order.
    pub fn from_layers(layout: Layout, planes: [Vec<[f32; 4]>; 3]) -> Self {
        assert!(planes.iter().all(|p| p.len() == layout.cells() as usize));
        Self { layout, planes }
    }

    pub fn index(&self, c: u32, cell: IVec3) -> usize {
        let n = self.layout.size as usize;
        ((c as usize * n + cell.z as usize) * n + cell.y as usize) * n + cell.x as usize
    }

    /// Cell `cell` of cascade `c`: `[red, green, blue]`.
    pub fn at(&self, c: u32, cell: IVec3) -> [[f64; 4]; 3] {
        let i = self.index(c, cell);
        self.planes.each_ref().map(|p| p[i].map(f64::from))
    }

    /// The flux (W) cascade `c` holds, per channel: every cell's intensity
    /// integrated over the sphere, `c0 * 2 sqrt(pi)`.
    pub fn flux(&self, c: u32) -> DVec3 {
        let n = (self.layout.size as usize).pow(3);
        let range = c as usize * n..(c as usize + 1) * n;
        let total = |p: &Vec<[f32; 4]>| p[range.clone()].iter().map(|v| v[0] as f64).sum::<f64>();
        DVec3::new(
            total(&self.planes[0]),
            total(&self.planes[1]),
            total(&self.planes[2]),
        ) * SH_FLUX
    }

    /// The irradiance (W/m^2, per channel) a point `p` with unit normal `n`
    /// reads from cascade `c` placed at `at`, as `cascade_irradiance` in
    /// `shaders/lpv/lookup.frag` does (half a cell along `n`, trilinear
    /// between cell centres, clamped to the grid).
    pub fn irradiance(&self, c: u32, at: &Cascade, p: DVec3, n: DVec3) -> DVec3 {
        let size = self.layout.size as f64;
        let h = at.cell as f64;
        let g = at.grid_position(p + 0.5 * h * n) - DVec3::splat(0.5);
        let lo = g.floor().clamp(DVec3::ZERO, DVec3::splat(size - 2.0));
        let f = (g - lo).clamp(DVec3::ZERO, DVec3::ONE);
        let mut sh = [[0f64; 4]; 3];
        for i in 0..8 {
            let o = IVec3::new(i & 1, (i >> 1) & 1, i >> 2);
            let t = DVec3::select(o.cmpeq(IVec3::ONE), f, DVec3::ONE - f);
            let w = t.x * t.y * t.z;
            let cell = self.at(c, lo.as_ivec3() + o);
            for (s, v) in sh.iter_mut().zip(cell) {
                for k in 0..4 {
                    s[k] += w * v[k];
                }
            }
        }
        let lobe = cosine_lobe(-n);
        let dot = |s: [f64; 4]| (0..4).map(|k| s[k] * lobe[k]).sum::<f64>().max(0.0) / (h * h);
        DVec3::new(dot(sh[0]), dot(sh[1]), dot(sh[2]))
    }

    /// How much of a point's irradiance cascade `c` at `at` gives (before the
    /// finer cascades take their share), as `lpv/lookup.frag` weighs it: 1
    /// inside, falling to 0 over the outer `blend_cells()` cell centres; the
    /// coarsest takes all of what is left within half a cell of its last
    /// centres.
    pub fn weight(&self, c: u32, at: &Cascade, p: DVec3, n: DVec3) -> f64 {
        let size = self.layout.size as f64;
        let g = at.grid_position(p + 0.5 * at.cell as f64 * n) - DVec3::splat(0.5);
        let inner = g.min(DVec3::splat(size - 1.0) - g).min_element();
        if c + 1 == self.layout.cascades {
            (inner >= -0.5) as u8 as f64
        } else {
            (inner / self.layout.blend_cells() as f64).clamp(0.0, 1.0)
        }
    }

    /// The irradiance `lpv/lookup.frag` writes for a point `p` with unit
    /// normal `n`: the finest cascade that holds it, blended into the next
    /// coarser one near its border.
    pub fn lookup(&self, cascades: &[Cascade], p: DVec3, n: DVec3) -> DVec3 {
        let mut e = DVec3::ZERO;
        let mut remaining = 1.0;
        for (c, at) in cascades.iter().enumerate() {
            if remaining <= 0.0 {
                break;
            }
            let w = self.weight(c as u32, at, p, n);
            if w > 0.0 {
                e += remaining * w * self.irradiance(c as u32, at, p, n);
                remaining *= 1.0 - w;
            }
        }
        e
    }
}
