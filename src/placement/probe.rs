//! What the placement looks at: the scene's surface as area-weighted
//! samples (robust bounds, the area seen from a direction) and as the path
//! tracer's BVH (rays that hit or escape).

use crate::pathtrace::bvh::{Bvh, Cull, Triangle};
use crate::scene::Scene;
use glam::{DVec3, Vec3A};

/// The scene's world triangles (relative to `Scene::origin`, as the scene
/// holds them), in f64.
pub(super) fn triangles(scene: &Scene) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    for inst in &scene.instances {
        let mesh = &scene.meshes[inst.mesh];
        let m = inst.world_from_object.as_dmat4();
        for t in mesh.indices.chunks_exact(3) {
            out.push(std::array::from_fn(|k| {
                m.transform_point3(
                    glam::Vec3::from(mesh.vertices[t[k] as usize].position).as_dvec3(),
                )
            }));
        }
    }
    out
}

fn area_normal(t: &[DVec3; 3]) -> DVec3 {
    (t[1] - t[0]).cross(t[2] - t[0]) * 0.5
}

/// Points spread over the surface in proportion to area: sample `k` lies
/// in the triangle where the cumulative area passes `(k + 1/2) / n` of the
/// total, at barycentric coordinates from the R2 sequence (deterministic,
/// so the same scene is always placed the same way).
pub(super) fn surface_samples(tris: &[[DVec3; 3]], n: usize) -> Vec<DVec3> {
    let mut cumulative = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in tris {
        total += area_normal(t).length();
        cumulative.push(total);
    }
    if total.is_nan() || total <= 0.0 {
        return tris.iter().flat_map(|t| t.iter().copied()).collect();
    }
    let (a1, a2) = (0.754_877_666_246_693, 0.569_840_290_998_053);
    (0..n)
        .map(|k| {
            let at = (k as f64 + 0.5) / n as f64 * total;
            let i = cumulative.partition_point(|&c| c < at).min(tris.len() - 1);
            let (mut u, mut v) = ((0.5 + a1 * k as f64).fract(), (0.5 + a2 * k as f64).fract());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let t = &tris[i];
            t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v
        })
        .collect()
}

/// The bounds of most of the surface, whatever lies far out: along each
/// axis, the 10th to 90th percentile of the samples (the core), widened by
/// the core's own width (or a quarter of the widest core, for a flat axis)
/// on each side, and the samples within that. A uniform spread reaches
/// 1/8 of its width past its core, so all of it is kept; a stray triangle
/// 100 km off, under a tenth of the area, is not.
pub(super) fn robust_bounds(samples: &[DVec3]) -> (DVec3, DVec3) {
    let sorted: [Vec<f64>; 3] = std::array::from_fn(|axis| {
        let mut v: Vec<f64> = samples.iter().map(|p| p[axis]).collect();
        v.sort_by(f64::total_cmp);
        v
    });
    let at = |v: &[f64], f: f64| v[((f * (v.len() - 1) as f64).round() as usize).min(v.len() - 1)];
    let core: [(f64, f64); 3] = std::array::from_fn(|a| (at(&sorted[a], 0.1), at(&sorted[a], 0.9)));
    let widest = core.iter().map(|(l, h)| h - l).fold(0.0, f64::max);
    let mut lo = DVec3::ZERO;
    let mut hi = DVec3::ZERO;
    for (axis, v) in sorted.iter().enumerate() {
        let (l, h) = core[axis];
        let margin = (h - l).max(0.25 * widest);
        let kept: Vec<f64> = v
            .iter()
            .copied()
            .filter(|&x| x >= l - margin && x <= h + margin)
            .collect();
        lo[axis] = kept.first().copied().unwrap_or(l);
        hi[axis] = kept.last().copied().unwrap_or(h);
    }
    (lo, hi)
}

/// The surface's area projected on a plane facing `view` (unit), both
/// sides counted (OBJ surfaces are double-sided).
pub(super) fn seen_area(tris: &[[DVec3; 3]], view: DVec3) -> f64 {
    tris.iter().map(|t| area_normal(t).dot(view).abs()).sum()
}

/// `n` unit directions spread evenly over the sphere (a Fibonacci lattice).
pub(super) fn sphere(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - (i as f64 + 0.5) / n as f64 * 2.0;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden * i as f64;
            DVec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

/// The scene's surface for rays, relative to `center` (f32 keeps its
/// precision near the part that matters).
pub(super) struct Rays {
    bvh: Bvh,
    center: DVec3,
}

/// What one ray found.
#[derive(Clone, Copy, Debug)]
pub(super) struct Found {
    pub t: f64,
    /// The surface there faces away from the ray's start (by the winding's
    /// normal): the start is likely inside a closed solid.
    pub back: bool,
}

impl Rays {
    pub(super) fn new(tris: &[[DVec3; 3]], center: DVec3) -> Self {
        let rel = |p: DVec3| Vec3A::from((p - center).as_vec3());
        let triangles = tris
            .iter()
            .map(|t| {
                let n = Vec3A::from(area_normal(t).normalize_or_zero().as_vec3());
                Triangle {
                    p: [rel(t[0]), rel(t[1]), rel(t[2])],
                    n: [n; 3],
                    uv: [[0.0; 2]; 3],
                    material: 0,
                    double_sided: true,
                }
            })
            .collect();
        Rays {
            bvh: Bvh::new(triangles),
            center,
        }
    }

    /// The nearest surface from `from` along unit `dir`, if any.
    pub(super) fn cast(&self, from: DVec3, dir: DVec3) -> Option<Found> {
        let o = Vec3A::from((from - self.center).as_vec3());
        let d = Vec3A::from(dir.as_vec3());
        let eps = (o.abs().max_element() * 1e-5).max(1e-30);
        self.bvh
            .intersect(o, d, eps, f32::INFINITY, false, Cull::BackFaces)
            .map(|h| Found {
                t: h.t as f64,
                back: self.bvh.triangles[h.triangle as usize].n[0].dot(d) > 0.0,
            })
    }
}
