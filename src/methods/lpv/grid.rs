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
    /// Cell side (m): a power of two.
    pub cell: f32,
    /// Where its lattice is anchored: the scene's min corner (relative to
    /// the render origin, as the frame uniforms carry it).
    pub anchor: Vec3,
    /// Its first cell, in whole cells from `anchor`.
    pub origin: IVec3,
}

impl Cascade {
    /// Point `p` in cell coordinates (cell `i` spans `[i, i + 1)`).
    pub fn grid_position(&self, p: DVec3) -> DVec3 {
        (p - self.anchor.as_dvec3()) / self.cell as f64 - self.origin.as_dvec3()
    }

    /// The world position of cell coordinates `g`.
    pub fn world(&self, g: DVec3) -> DVec3 {
        self.anchor.as_dvec3() + (g + self.origin.as_dvec3()) * self.cell as f64
    }

    /// The cascade's box: its first cell's min corner and its last cell's
    /// max corner, for `size` cells a side.
    pub fn bounds(&self, size: u32) -> (DVec3, DVec3) {
        (
            self.world(DVec3::ZERO),
            self.world(DVec3::splat(size as f64)),
        )
    }
}

/// How far ahead of the camera a cascade's centre aims, in sides
/// (specialization constant `LPV_AHEAD`): 3/8, so that an eighth of it lies
/// behind the camera and the rest where it looks (the paper shifts its
/// cascades along the view direction too).
pub const AHEAD: f32 = 0.375;

/// The coarsest cascade's cell exponent for a scene of bounds `lo`..`hi`
/// and `size` cells a side: the smallest `k` with `(size - 3) 2^k` at or
/// above the bounds' largest side, 0 for an empty scene
/// (`lpv_top_exponent`).
pub fn top_exponent(lo: Vec3, hi: Vec3, size: u32) -> i32 {
    let side = (hi - lo).max_element();
    // An empty or degenerate (NaN) scene: cells of 1 m.
    if side.is_nan() || side <= 0.0 {
        return 0;
    }
    let room = (size - 3) as f32;
    let mut k = (side / room).log2().ceil() as i32;
    if room * 2f32.powi(k - 1) >= side {
        k -= 1;
    }
    if room * 2f32.powi(k) < side {
        k += 1;
    }
    k
}

/// The cascades of a frame with uniforms `u`, finest first, computed in f32
/// as the shaders do (`lpv_origin`): the coarsest holds the scene's bounds,
/// each finer one halves the cell, and each aims `AHEAD` of its side ahead
/// of the camera, kept within the bounds widened by a cell (or at their
/// middle where it is wider), snapped to whole cells from the scene's min
/// corner.
pub fn cascades(u: &FrameUniforms, layout: &Layout) -> Vec<Cascade> {
    let n = layout.size;
    let (lo, hi) = (Vec3::from(u.scene_min), Vec3::from(u.scene_max));
    let top = top_exponent(lo, hi, n);
    let camera = Vec3::from(u.camera_position);
    let forward = Vec3::from(u.camera_forward);
    (0..layout.cascades as i32)
        .map(|c| {
            let k = top + c - (layout.cascades as i32 - 1);
            let h = 2f32.powi(k);
            let side = n as f32 * h;
            let aim = camera + forward * (AHEAD * side);
            let (a, b) = (
                lo - Vec3::splat(h) + Vec3::splat(0.5 * side),
                hi + Vec3::splat(h) - Vec3::splat(0.5 * side),
            );
            let middle = 0.5 * (lo + hi);
            let centre = Vec3::select(b.cmplt(a), middle, aim.max(a).min(b));
            let cells = (centre - lo) * 2f32.powi(-k);
            let origin = cells.floor().as_ivec3() - IVec3::splat(n as i32 / 2);
            Cascade {
                cell: h,
                anchor: lo,
                origin,
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn layout(size: u32, cascades: u32) -> Layout {
        Layout {
            size,
            cascades,
            iterations: size,
            occlusion: true,
            vpl_level: 0,
            gbuffer_stride: 1,
        }
    }

    /// The frame uniforms placement reads: the scene's bounds and the camera.
    fn frame(lo: Vec3, hi: Vec3, camera: Vec3, forward: Vec3) -> FrameUniforms {
        FrameUniforms {
            scene_min: lo.to_array(),
            scene_max: hi.to_array(),
            camera_position: camera.to_array(),
            camera_forward: forward.normalize().to_array(),
            ..Default::default()
        }
    }

    /// A deterministic stream of numbers in [0, 1) (splitmix64).
    struct Numbers(u64);

    impl Numbers {
        fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }

        fn vec(&mut self) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next())
        }

        /// A scene's bounds: sides from 5 cm to 80 m, within four sides of
        /// the render origin (positions are relative to it, which lies
        /// near the camera).
        fn bounds(&mut self) -> (Vec3, Vec3) {
            let side = 0.05 * 1600f32.powf(self.next());
            let lo = (self.vec() - 0.5) * 8.0 * side;
            // Some flat (a floor), the rest boxes of any proportions.
            let mut shape = self.vec().max(Vec3::splat(0.05));
            if self.next() < 0.2 {
                shape.y = 0.0;
            }
            (lo, lo + side * shape / shape.max_element())
        }
    }

    fn contains(b: (DVec3, DVec3), p: DVec3) -> bool {
        p.cmpge(b.0).all() && p.cmple(b.1).all()
    }

    /// The distance from `p` to the box `b` (0 inside).
    fn distance(b: (DVec3, DVec3), p: DVec3) -> f64 {
        (b.0 - p).max(p - b.1).max(DVec3::ZERO).length()
    }

    #[test]
    fn the_coarsest_cascade_holds_the_scene_and_the_finest_the_camera() {
        let mut numbers = Numbers(1);
        for _ in 0..4000 {
            let (lo, hi) = numbers.bounds();
            let size = [8, 16, 32, 64][(numbers.next() * 4.0) as usize];
            let count = 1 + (numbers.next() * 4.0) as u32;
            let l = layout(size, count);
            // Half the cameras inside the bounds, half anywhere near them.
            let camera = match numbers.next() < 0.5 {
                true => lo + (hi - lo) * numbers.vec(),
                false => lo + (hi - lo) * (numbers.vec() * 4.0 - 1.5),
            };
            let forward = numbers.vec() - 0.5;
            let c = cascades(&frame(lo, hi, camera, forward), &l);
            let what = format!("bounds {lo}..{hi}, camera {camera} looking {forward}, {l:?}");
            let top = c[c.len() - 1];
            // The coarsest cell: the smallest power of two with (N - 3) h at
            // or above the largest side.
            let side = (hi - lo).max_element();
            let h = top.cell;
            assert_eq!(h, 2f32.powi(h.log2() as i32), "{what}");
            assert!((size - 3) as f32 * h >= side, "{what}");
            assert!((size - 3) as f32 * h * 0.5 < side || side == 0.0, "{what}");
            // Each finer cascade halves it.
            for (k, at) in c.iter().enumerate() {
                let finer = count as i32 - 1 - k as i32;
                assert_eq!(at.cell, h * 2f32.powi(-finer), "{what}");
            }
            // The coarsest holds the bounds with a cell to spare on every
            // side: every injection and lookup point (half a cell off a
            // surface) and the trilinear lookup's cell centres. The margin
            // is a cell less 1e-3 for the f32 rounding of the bounds.
            let box_ = top.bounds(size);
            let spare = DVec3::splat(0.999 * h as f64);
            for corner in [lo.as_dvec3() - spare, hi.as_dvec3() + spare] {
                assert!(contains(box_, corner), "{what}: {box_:?}");
            }
            // The finest holds the camera when the camera is in the scene;
            // from outside, it lies on the scene's side nearest the camera
            // (no farther from it than the bounds).
            let finest = c[0].bounds(size);
            let camera = camera.as_dvec3();
            let scene = (lo.as_dvec3(), hi.as_dvec3());
            if contains(scene, camera) {
                assert!(contains(finest, camera), "{what}: {finest:?}");
            } else {
                let (d, d_scene) = (distance(finest, camera), distance(scene, camera));
                assert!(d <= d_scene * (1.0 + 1e-6), "{what}: {d} > {d_scene}");
            }
            // Where a cascade is no wider than the bounds it stays within
            // them, widened by two cells (one, and one for the snap).
            for at in &c {
                let (a, b) = at.bounds(size);
                let two = 2.0 * at.cell as f64 * (1.0 + 1e-6);
                for axis in 0..3 {
                    let width = (hi[axis] - lo[axis]) as f64 + 2.0 * at.cell as f64;
                    if size as f64 * (at.cell as f64) <= width {
                        assert!(a[axis] >= lo[axis] as f64 - two, "{what}: {a} {b}");
                        assert!(b[axis] <= hi[axis] as f64 + two, "{what}: {a} {b}");
                    }
                }
            }
        }
    }

    #[test]
    fn the_cascades_move_by_whole_cells_with_the_camera() {
        // The Cornell box (2 m) from inside, 32 cells, 3 cascades: cells of
        // 1/32, 1/16 and 1/8 m (29 / 8 m is the first multiple at or above 2).
        let (lo, hi) = (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 1.0));
        let l = layout(32, 3);
        let forward = -Vec3::Z;
        let place = |camera: Vec3| cascades(&frame(lo, hi, camera, forward), &l);
        let h = place(Vec3::ZERO)[0].cell;
        assert_eq!(h, 1.0 / 32.0);
        // A camera whose finest cascade's aim (3/8 of 32 cells, 12 cells,
        // ahead) is a cell's centre: then translations of under half a
        // finest cell keep every cascade where it is (the coarser ones'
        // cells are 2 and 4 times as wide, their aims a quarter or an eighth
        // of a cell from their centres).
        let camera = lo + Vec3::new(20.5, 30.5, 40.5) * h;
        let base = place(camera);
        for t in [
            Vec3::new(0.3, 0.0, 0.0),
            Vec3::new(-0.45, 0.2, 0.1),
            Vec3::new(0.0, -0.49, 0.49),
            Vec3::new(0.1, 0.1, -0.3),
        ] {
            assert_eq!(place(camera + t * h), base, "moved {t} cells");
        }
        // Any translation of under a cell of a cascade moves it by whole
        // cells, at most one per axis, and keeps its cell.
        let mut numbers = Numbers(2);
        for _ in 0..2000 {
            let from = lo + (hi - lo) * numbers.vec();
            let forward = numbers.vec() - 0.5;
            let at = |camera: Vec3| cascades(&frame(lo, hi, camera, forward), &l);
            let a = at(from);
            let t = (numbers.vec() * 2.0 - 1.0) * 0.999;
            for (c, before) in a.iter().enumerate() {
                let after = at(from + t * before.cell)[c];
                assert_eq!(after.cell, before.cell);
                assert_eq!(after.anchor, before.anchor);
                let moved = after.origin - before.origin;
                assert!(moved.abs().max_element() <= 1, "cascade {c}: {moved}");
            }
        }
        // One finest cell along x moves the finest cascade by one cell.
        let moved = place(camera + Vec3::X * h);
        assert_eq!(moved[0].origin, base[0].origin + IVec3::X);
    }
}
