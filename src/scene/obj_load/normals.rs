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
//! smooth (area-weighted), clusters are apart. Linear in the corners, and
//! at most [`MAX_CLUSTERS`] per position: a corner that fits none of them
//! joins the nearest (a hostile fan of 10^6 faces in all directions around
//! one point makes 8 vertices there, not 10^6). The vertices made are
//! counted before they are made, against the vertex budget.

use crate::scene::GpuVertex;
use anyhow::{bail, Result};
use glam::{DVec3, Vec3};
use std::collections::HashMap;

/// Faces closer than this in orientation are smoothed together.
pub const CREASE_DEGREES: f32 = 60.0;
const MAX_CLUSTERS: usize = 8;

/// Twice the area vector of triangle `t`, in f64: no square under- or
/// overflows at any scale f32 positions have.
fn face(vertices: &[GpuVertex], t: &[u32]) -> DVec3 {
    let p = |i: u32| Vec3::from(vertices[i as usize].position).as_dvec3();
    (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]))
}

/// Normals for `vertices` (positions and texture coordinates as read) and
/// the triangles `indices`, none degenerate: vertices are split where a
/// position's faces fall into clusters. Returns the vertices (each keeps
/// its place for its first cluster; splits are appended) and the indices
/// (rewritten in place), or an error, before the vertices are made, if
/// they would be more than `max_vertices`. Memory: a few words a corner.
pub fn crease_normals(
    vertices: Vec<GpuVertex>,
    mut indices: Vec<u32>,
    max_vertices: u64,
) -> Result<(Vec<GpuVertex>, Vec<u32>)> {
    let corners = indices.len();
    let cluster = clusters(&vertices, &indices);
    let (cluster, sums) = (cluster.0, cluster.1);
    // Each vertex keeps its slot for the first cluster it is met with (the
    // only one where the surface is smooth); a vertex on a crease gets one
    // more vertex for each other cluster, appended. Counted first.
    let mut slot = vec![u32::MAX; vertices.len()];
    let mut split: HashMap<(u32, u32), u32> = HashMap::new();
    let mut made = vertices.len() as u64;
    for c in 0..corners {
        let (i, k) = (indices[c], cluster[c]);
        let s = &mut slot[i as usize];
        if *s == u32::MAX {
            *s = k;
        } else if *s != k {
            if let std::collections::hash_map::Entry::Vacant(e) = split.entry((i, k)) {
                e.insert(made as u32);
                made += 1;
                if made > max_vertices {
                    bail!(
                        "the normals computed for faces without them (crease angle {CREASE_DEGREES} degrees) need more than {max_vertices} vertices in all, the limit; give the faces normals (vn)"
                    );
                }
            }
        }
    }
    let mut vertices = vertices;
    vertices.reserve_exact(split.len());
    for (c, index) in indices.iter_mut().enumerate() {
        let (i, k) = (*index, cluster[c]);
        let normal = sums[k as usize].normalize_or(DVec3::Y).as_vec3().to_array();
        if slot[i as usize] == k {
            vertices[i as usize].normal = normal;
        } else {
            let j = split[&(i, k)];
            if j as usize == vertices.len() {
                vertices.push(GpuVertex {
                    normal,
                    ..vertices[i as usize]
                });
            }
            *index = j;
        }
    }
    Ok((vertices, indices))
}

/// Each corner's cluster, and each cluster's area-weighted normal sum.
fn clusters(vertices: &[GpuVertex], indices: &[u32]) -> (Vec<u32>, Vec<DVec3>) {
    let corners = indices.len();
    // Each vertex's point (the same point under several texture
    // coordinates, or on several `v` lines, is one point).
    let key = |v: &GpuVertex| v.position.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
    let mut points: HashMap<[u32; 3], u32> = HashMap::new();
    let point: Vec<u32> = vertices
        .iter()
        .map(|v| {
            let n = points.len() as u32;
            *points.entry(key(v)).or_insert(n)
        })
        .collect();
    let groups = points.len();
    drop(points);
    // Corners grouped by point, in corner order within a group.
    let mut start = vec![0u32; groups + 1];
    for &i in indices {
        start[point[i as usize] as usize + 1] += 1;
    }
    for g in 0..groups {
        start[g + 1] += start[g];
    }
    let mut order = vec![0u32; corners];
    let mut fill = start.clone();
    for (c, &i) in indices.iter().enumerate() {
        let g = point[i as usize] as usize;
        order[fill[g] as usize] = c as u32;
        fill[g] += 1;
    }
    drop(fill);
    drop(point);
    let cos = (CREASE_DEGREES as f64).to_radians().cos();
    let mut cluster = vec![0u32; corners];
    let mut sums: Vec<DVec3> = Vec::new();
    let mut reps: Vec<DVec3> = Vec::with_capacity(MAX_CLUSTERS);
    for g in 0..groups {
        let first = sums.len();
        reps.clear();
        for &c in &order[start[g] as usize..start[g + 1] as usize] {
            let t = c as usize / 3;
            let f = face(vertices, &indices[3 * t..3 * t + 3]);
            let unit = f.normalize_or_zero();
            let k = match reps.iter().position(|r| r.dot(unit) >= cos) {
                Some(k) => k,
                None if reps.len() < MAX_CLUSTERS => {
                    reps.push(unit);
                    sums.push(DVec3::ZERO);
                    reps.len() - 1
                }
                // The nearest cluster, past the cap.
                None => (0..reps.len())
                    .max_by(|&a, &b| reps[a].dot(unit).total_cmp(&reps[b].dot(unit)))
                    .unwrap_or(0),
            };
            sums[first + k] += f;
            cluster[c as usize] = (first + k) as u32;
        }
    }
    (cluster, sums)
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
        let (out, i) = crease_normals(verts, idx.clone(), 100).unwrap();
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
        let (out, _) = crease_normals(verts, idx, 100).unwrap();
        assert_eq!(out.len(), 4);
    }
}
