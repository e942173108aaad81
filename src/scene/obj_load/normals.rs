//! Vertex normals for an OBJ mesh that has none, with a crease angle.
//!
//! `scene::compute_normals` averages every face around a vertex, which is
//! right for a smooth surface (the bunny) and wrong where faces meet at a
//! hard edge: in the conference room, whose vertices are shared by table
//! tops and their sides, floors and walls, 32% of the corners would get a
//! normal more than 30 degrees off their own face (16% more than 60), and
//! flat walls would shade like cushions. OBJ says the same with smoothing
//! groups, whose default is none (flat); the archives seldom write them.
//! So the faces around a position are split into clusters whose normals lie
//! within [`CREASE_DEGREES`] of the cluster's first face: each cluster is
//! smooth (area-weighted), clusters are apart. Linear in the corners: at
//! most [`MAX_CLUSTERS`] per position, corners beyond them keep their
//! face's normal (a hostile fan of 10^6 faces around one point costs
//! nothing more).

use crate::scene::GpuVertex;
use glam::Vec3;
use std::collections::HashMap;

/// Faces closer than this in orientation are smoothed together.
pub const CREASE_DEGREES: f32 = 60.0;
const MAX_CLUSTERS: usize = 8;

/// Normals for `vertices` (positions and texture coordinates as read) and
/// the triangles `indices`, none degenerate: vertices are split where a
/// position's faces fall into clusters. Returns the new vertices and indices.
pub fn crease_normals(vertices: &[GpuVertex], indices: &[u32]) -> (Vec<GpuVertex>, Vec<u32>) {
    // Positions scaled to about unit size, as `compute_normals` does.
    let scale = crate::scene::unit_scale(vertices);
    let triangles = indices.len() / 3;
    let face: Vec<Vec3> = indices
        .chunks_exact(3)
        .map(|t| {
            let p = |k: usize| Vec3::from(vertices[t[k] as usize].position) * scale;
            (p(1) - p(0)).cross(p(2) - p(0))
        })
        .collect();
    let unit: Vec<Vec3> = face.iter().map(|n| n.normalize_or_zero()).collect();
    // Corners grouped by position (the same point under several texture
    // coordinates is one point).
    let key = |v: &GpuVertex| v.position.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
    let mut groups: HashMap<[u32; 3], u32> = HashMap::new();
    let group: Vec<u32> = indices
        .iter()
        .map(|&i| {
            let n = groups.len() as u32;
            *groups.entry(key(&vertices[i as usize])).or_insert(n)
        })
        .collect();
    let mut order: Vec<u32> = (0..indices.len() as u32).collect();
    order.sort_by_key(|&c| group[c as usize]);
    let cos = CREASE_DEGREES.to_radians().cos();
    // Per corner: its cluster (an index into `sums`) or none (its face's normal).
    let mut cluster = vec![u32::MAX; indices.len()];
    let mut sums: Vec<Vec3> = Vec::new();
    let mut start = 0;
    while start < order.len() {
        let g = group[order[start] as usize];
        let end = start + order[start..].partition_point(|&c| group[c as usize] == g);
        let first = sums.len();
        let mut reps: Vec<Vec3> = Vec::new();
        for &c in &order[start..end] {
            let t = c as usize / 3;
            let found = reps.iter().position(|r| r.dot(unit[t]) >= cos);
            let k = match found {
                Some(k) => Some(k),
                None if reps.len() < MAX_CLUSTERS => {
                    reps.push(unit[t]);
                    sums.push(Vec3::ZERO);
                    Some(reps.len() - 1)
                }
                None => None,
            };
            if let Some(k) = k {
                sums[first + k] += face[t];
                cluster[c as usize] = (first + k) as u32;
            }
        }
        start = end;
    }
    let mut out_vertices = Vec::with_capacity(vertices.len());
    let mut out_indices = Vec::with_capacity(indices.len());
    let mut made: HashMap<(u32, u32), u32> = HashMap::new();
    for (c, &i) in indices.iter().enumerate() {
        let t = c / 3;
        let normal = match cluster[c] {
            u32::MAX => unit[t],
            k => sums[k as usize].normalize_or(unit[t]),
        };
        let new = |out: &mut Vec<GpuVertex>| {
            out.push(GpuVertex {
                normal: normal.normalize_or(Vec3::Y).to_array(),
                ..vertices[i as usize]
            });
            (out.len() - 1) as u32
        };
        let index = if cluster[c] == u32::MAX {
            new(&mut out_vertices)
        } else {
            *made
                .entry((i, cluster[c]))
                .or_insert_with(|| new(&mut out_vertices))
        };
        out_indices.push(index);
    }
    debug_assert_eq!(out_indices.len(), triangles * 3);
    (out_vertices, out_indices)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(p: [f32; 3]) -> GpuVertex {
        GpuVertex {
            position: p,
            ..Default::default()
        }
    }

    #[test]
    fn a_hard_edge_is_kept_and_a_gentle_one_smoothed() {
        // Two triangles meeting at 90 degrees along the edge (0,0,0)-(1,0,0):
        // a floor (+Y) and a wall (+Z).
        let verts = vec![
            v([0., 0., 0.]),
            v([1., 0., 0.]),
            v([1., 0., -1.]),
            v([0., 1., 0.]),
        ];
        let idx = vec![0, 1, 2, 1, 0, 3];
        let (out, i) = crease_normals(&verts, &idx);
        // The shared edge's two vertices are split: four + two.
        assert_eq!(out.len(), 6);
        for t in i.chunks_exact(3) {
            let n: Vec<Vec3> = t
                .iter()
                .map(|&k| Vec3::from(out[k as usize].normal))
                .collect();
            assert!(n.iter().all(|x| x.abs_diff_eq(n[0], 1e-6)), "{n:?}");
        }
        // At 20 degrees apart they are smoothed: shared vertices stay shared.
        let a = 20f32.to_radians();
        let verts = vec![
            v([0., 0., 0.]),
            v([1., 0., 0.]),
            v([1., 0., -1.]),
            v([0., a.sin(), a.cos()]),
        ];
        let (out, _) = crease_normals(&verts, &idx);
        assert_eq!(out.len(), 4);
    }
}
