//! A bounding-volume hierarchy over the scene's world-space triangles for the
//! CPU path tracer: median split on the longest axis of the centroid bounds,
//! leaves of up to four triangles, iterative traversal with a stack.

use glam::Vec3A;

/// A world-space triangle with what shading needs.
#[derive(Clone, Debug)]
pub struct Triangle {
    pub p: [Vec3A; 3],
    pub n: [Vec3A; 3],
    pub uv: [[f32; 2]; 3],
    pub material: u32,
    /// Back faces of single-sided materials are invisible, as when rasterizing.
    pub double_sided: bool,
}

/// Which side of single-sided triangles a ray ignores, to see what the
/// rasterizer sees: camera and bounce rays skip back faces (as culling does);
/// shadow rays, which travel towards the light, skip the faces turned away
/// from it (the RSM keeps only faces turned towards the light).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cull {
    /// Skip single-sided triangles hit from behind.
    BackFaces,
    /// Skip single-sided triangles hit from the front.
    FrontFaces,
}

/// Where a ray hit, in barycentric terms.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    pub triangle: u32,
    pub u: f32,
    pub v: f32,
}

#[derive(Clone, Copy)]
struct Node {
    lo: Vec3A,
    hi: Vec3A,
    /// Leaf: first triangle index; inner: index of the left child (right = left + 1).
    start: u32,
    /// Leaf: triangle count (> 0); inner: 0.
    count: u32,
}

pub struct Bvh {
    nodes: Vec<Node>,
    /// Triangle indices in leaf order.
    order: Vec<u32>,
    pub triangles: Vec<Triangle>,
}

const LEAF_SIZE: usize = 4;

fn bounds(tris: &[Triangle], ids: &[u32]) -> (Vec3A, Vec3A) {
    let mut lo = Vec3A::splat(f32::INFINITY);
    let mut hi = Vec3A::splat(f32::NEG_INFINITY);
    for &i in ids {
        for p in tris[i as usize].p {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    (lo, hi)
}

impl Bvh {
    pub fn new(triangles: Vec<Triangle>) -> Self {
        let mut bvh = Self {
            nodes: Vec::with_capacity(2 * triangles.len() / LEAF_SIZE + 1),
            order: (0..triangles.len() as u32).collect(),
            triangles,
        };
        let (lo, hi) = bounds(&bvh.triangles, &bvh.order);
        bvh.nodes.push(Node {
            lo,
            hi,
            start: 0,
            count: bvh.order.len() as u32,
        });
        let mut pending = vec![0usize];
        while let Some(n) = pending.pop() {
            let Node { start, count, .. } = bvh.nodes[n];
            if (count as usize) <= LEAF_SIZE {
                continue;
            }
            let range = start as usize..(start + count) as usize;
            let centroid = |i: u32| {
                let p = &bvh.triangles[i as usize].p;
                (p[0] + p[1] + p[2]) / 3.0
            };
            let (mut clo, mut chi) = (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY));
            for &i in &bvh.order[range.clone()] {
                clo = clo.min(centroid(i));
                chi = chi.max(centroid(i));
            }
            let extent = chi - clo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let mid = range.len() / 2;
            bvh.order[range.clone()].select_nth_unstable_by(mid, |&a, &b| {
                centroid(a)[axis].total_cmp(&centroid(b)[axis])
            });
            let left = bvh.nodes.len();
            for (s, c) in [
                (start, mid as u32),
                (start + mid as u32, count - mid as u32),
            ] {
                let (lo, hi) = bounds(&bvh.triangles, &bvh.order[s as usize..(s + c) as usize]);
                bvh.nodes.push(Node {
                    lo,
                    hi,
                    start: s,
                    count: c,
                });
            }
            bvh.nodes[n] = Node {
                start: left as u32,
                count: 0,
                ..bvh.nodes[n]
            };
            pending.extend([left, left + 1]);
        }
        bvh
    }

    /// The nearest hit with `t` in (`t_min`, `t_max`); `any` stops at the first
    /// hit found (shadow rays).
    pub fn intersect(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_min: f32,
        t_max: f32,
        any: bool,
        cull: Cull,
    ) -> Option<Hit> {
        if self.triangles.is_empty() {
            return None;
        }
        let inv = dir.recip();
        let mut best: Option<Hit> = None;
        let mut t_far = t_max;
        let mut stack = [0u32; 64];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let node = self.nodes[stack[sp] as usize];
            // Slab test.
            let t0 = (node.lo - origin) * inv;
            let t1 = (node.hi - origin) * inv;
            let near = t0.min(t1).max_element().max(t_min);
            let far = t0.max(t1).min_element().min(t_far);
            if near > far {
                continue;
            }
            if node.count == 0 {
                if sp + 2 <= stack.len() {
                    stack[sp] = node.start;
                    stack[sp + 1] = node.start + 1;
                    sp += 2;
                }
                continue;
            }
            for &i in &self.order[node.start as usize..(node.start + node.count) as usize] {
                if let Some((t, u, v)) = self.hit_triangle(i, origin, dir, t_min, t_far, cull) {
                    t_far = t;
                    best = Some(Hit {
                        t,
                        triangle: i,
                        u,
                        v,
                    });
                    if any {
                        return best;
                    }
                }
            }
        }
        best
    }

    /// Möller-Trumbore, skipping one side of single-sided triangles.
    fn hit_triangle(
        &self,
        i: u32,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
        cull: Cull,
    ) -> Option<(f32, f32, f32)> {
        let tri = &self.triangles[i as usize];
        let e1 = tri.p[1] - tri.p[0];
        let e2 = tri.p[2] - tri.p[0];
        let pv = d.cross(e2);
        let det = e1.dot(pv);
        // det > 0: the ray meets the counter-clockwise (front) side.
        let skipped = match cull {
            Cull::BackFaces => det < 0.0,
            Cull::FrontFaces => det > 0.0,
        };
        // A ray (nearly) in the triangle's plane misses it. The bound scales
        // with the edges (det is their product): an absolute 1e-12 refused
        // every triangle of a scene 1e-6 m across, whose edges' products are
        // about that size, and left `pathtrace` black there.
        let scale = e1.abs().max_element() * e2.abs().max_element();
        if det.abs() <= 1e-12 * scale || (!tri.double_sided && skipped) {
            return None;
        }
        let inv = 1.0 / det;
        let tv = o - tri.p[0];
        let u = tv.dot(pv) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let qv = tv.cross(e1);
        let v = d.dot(qv) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = e2.dot(qv) * inv;
        (t > t_min && t < t_max).then_some((t, u, v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(z: f32, double_sided: bool) -> Triangle {
        Triangle {
            p: [
                Vec3A::new(-1.0, -1.0, z),
                Vec3A::new(1.0, -1.0, z),
                Vec3A::new(0.0, 1.0, z),
            ],
            n: [Vec3A::Z; 3],
            uv: [[0.0; 2]; 3],
            material: 0,
            double_sided,
        }
    }

    #[test]
    fn nearest_hit_among_many_and_back_faces_skipped() {
        let tris: Vec<Triangle> = (0..50)
            .map(|i| tri(-(i as f32) - 1.0, i % 2 == 1))
            .collect();
        let bvh = Bvh::new(tris);
        let cast = |o: Vec3A, d: Vec3A, any: bool, cull: Cull| {
            bvh.intersect(o, d, 1e-4, f32::INFINITY, any, cull)
        };
        // Looking down -z from +z: front faces (normal +z) face the ray.
        let hit = cast(Vec3A::new(0.0, 0.0, 5.0), -Vec3A::Z, false, Cull::BackFaces).unwrap();
        assert_eq!(hit.triangle, 0);
        assert!((hit.t - 6.0).abs() < 1e-5);
        // From behind, single-sided triangles (even i) are invisible: the first
        // hit is the double-sided one nearest to z = -60.
        let back = cast(
            Vec3A::new(0.0, 0.0, -60.0),
            Vec3A::Z,
            false,
            Cull::BackFaces,
        )
        .unwrap();
        assert_eq!(back.triangle, 49);
        // Culling front faces instead: from +z, the first hit is double-sided.
        let front = cast(
            Vec3A::new(0.0, 0.0, 5.0),
            -Vec3A::Z,
            false,
            Cull::FrontFaces,
        )
        .unwrap();
        assert_eq!(front.triangle, 1);
        assert!(cast(Vec3A::new(3.0, 0.0, 5.0), -Vec3A::Z, true, Cull::BackFaces).is_none());
        let empty = Bvh::new(vec![]);
        assert!(empty
            .intersect(
                Vec3A::ZERO,
                Vec3A::Z,
                0.0,
                f32::INFINITY,
                false,
                Cull::BackFaces
            )
            .is_none());
    }
}
