//! The meshes of an OBJ, built as its faces are read: one mesh per material
//! (not per group or per `usemtl` switch: a file alternating two materials
//! a million times makes two meshes), each vertex made once per distinct
//! (position, texture coordinate, normal) and counted against the budget
//! when it first appears, at the line of its face.
//!
//! Merging by material puts a material's triangles in one mesh in the order
//! the file gives them; where they were split into several meshes before,
//! the renderer draws them in another order. Rasterized images differ only
//! where two surfaces are at exactly the same depth (each pixel takes the
//! nearest surface whatever the order, the depth test keeping the first of
//! equals); the order of accumulation in GPU passes is per pixel, not per
//! triangle. `tests/obj_hostile.rs` checks a scene split by groups and
//! material switches renders within float rounding of the same scene in
//! one piece.

use super::{normals, State, NONE};
use crate::scene::GpuVertex;
use anyhow::{bail, Result};
use glam::DVec3;
use std::collections::hash_map::{Entry, HashMap};

/// The vertex data of the file, as the lines define it (0-based).
#[derive(Default)]
pub(super) struct Geometry {
    pub positions: Vec<[f32; 3]>,
    pub texcoords: Vec<[f32; 2]>,
    /// Unit normals; zero for a `vn` without a direction (faces using it
    /// get computed normals).
    pub normals: Vec<[f32; 3]>,
}

impl Geometry {
    fn position(&self, v: u32) -> DVec3 {
        glam::Vec3::from(self.positions[v as usize]).as_dvec3()
    }

    /// Twice the area vector of the triangle of positions `v`, in f64 (no
    /// f32 square under- or overflows, at any scale the budgets allow).
    fn cross(&self, v: [u32; 3]) -> DVec3 {
        let p0 = self.position(v[0]);
        (self.position(v[1]) - p0).cross(self.position(v[2]) - p0)
    }
}

/// Vertices and triangles of one mesh part, each vertex once.
#[derive(Default)]
pub(super) struct Part {
    map: HashMap<[u32; 3], u32>,
    /// Each vertex's (position, texture coordinate, normal) indices.
    keys: Vec<[u32; 3]>,
    /// Three vertex indices a triangle.
    indices: Vec<u32>,
}

impl Part {
    /// The vertex of `key`, made when new and counted in `distinct`
    /// against `limit`.
    fn vertex(&mut self, key: [u32; 3], distinct: &mut u64, limit: u64) -> Result<u32> {
        let next = self.keys.len() as u32;
        match self.map.entry(key) {
            Entry::Occupied(e) => Ok(*e.get()),
            Entry::Vacant(e) => {
                *distinct += 1;
                if *distinct > limit {
                    bail!(
                        "the faces so far make more than {limit} distinct vertices (combinations of position, texture coordinate and normal); the limit is {limit}"
                    );
                }
                e.insert(next);
                self.keys.push(key);
                Ok(next)
            }
        }
    }
}

/// The triangles of one material: those whose corners all have a normal
/// from the file, and those whose normals are computed.
pub(super) struct MeshBuilder {
    /// The material's index in `Materials::list`; `None`: the default.
    pub material: Option<u32>,
    given: Part,
    computed: Part,
}

impl State {
    /// Makes `material` the one of the faces that follow.
    pub(super) fn select(&mut self, material: Option<u32>) {
        if self.current != material {
            self.current = material;
            self.current_mesh = None;
        }
    }

    /// The index in `meshes` of the current material's mesh.
    fn mesh(&mut self) -> usize {
        if let Some(m) = self.current_mesh {
            return m;
        }
        let material = self.current;
        let meshes = &mut self.meshes;
        let m = *self.mesh_of.entry(material).or_insert_with(|| {
            meshes.push(MeshBuilder {
                material,
                given: Part::default(),
                computed: Part::default(),
            });
            meshes.len() - 1
        });
        self.current_mesh = Some(m);
        m
    }

    /// Adds one triangle of corners (position, texture coordinate, normal;
    /// [`NONE`] where absent) to the current material's mesh: skipped when
    /// degenerate, turned when wound against its normals.
    pub(super) fn triangle(&mut self, corners: [[u32; 3]; 3]) -> Result<()> {
        let g = &self.geometry;
        let v = corners.map(|c| c[0]);
        let cross = g.cross(v);
        if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] || cross == DVec3::ZERO {
            self.tally.degenerate += 1;
            return Ok(());
        }
        let normal = |c: &[u32; 3]| {
            (c[2] != NONE)
                .then(|| glam::Vec3::from(g.normals[c[2] as usize]))
                .filter(|n| *n != glam::Vec3::ZERO)
        };
        let normals = [&corners[0], &corners[1], &corners[2]].map(normal);
        let given = normals.iter().all(Option::is_some);
        let mut corners = corners;
        if given {
            // Shading flips the normal of a face seen from behind (double
            // sided), which is right only if the normals are on the side
            // the winding calls the front: a face wound against its normals
            // is turned, so the file's normals say where its front is.
            let sum: DVec3 = normals.iter().flatten().map(|n| n.as_dvec3()).sum();
            if sum.dot(cross) < 0.0 {
                corners.swap(1, 2);
                let at = self.here();
                self.tally.rewound.add(|| at);
            }
        } else {
            self.tally.computed += 1;
        }
        let limit = self.options.limits.vertices;
        let m = self.mesh();
        let mesh = &mut self.meshes[m];
        let part = if given {
            &mut mesh.given
        } else {
            &mut mesh.computed
        };
        for c in corners {
            let key = if given { c } else { [c[0], c[1], NONE] };
            let index = part.vertex(key, &mut self.distinct, limit)?;
            part.indices.push(index);
        }
        Ok(())
    }
}

/// The vertices and triangles of `mesh`: the file's normals where every
/// corner has one, computed (with a crease angle) for the other triangles,
/// within `max_vertices` (what the budget leaves).
pub(super) fn finish(
    mesh: MeshBuilder,
    g: &Geometry,
    max_vertices: u64,
) -> Result<(Vec<GpuVertex>, Vec<u32>)> {
    let (mut vertices, mut indices) = vertices_of(mesh.given, g);
    let (computed, computed_indices) = vertices_of(mesh.computed, g);
    if !computed_indices.is_empty() {
        let left = max_vertices.saturating_sub(vertices.len() as u64);
        let (v, i) = normals::crease_normals(computed, computed_indices, left)?;
        let base = vertices.len() as u32;
        vertices.extend(v);
        indices.extend(i.into_iter().map(|k| k + base));
    }
    Ok((vertices, indices))
}

/// A part's vertices (normals from the file, or zero) and indices; its
/// map is dropped first.
fn vertices_of(part: Part, g: &Geometry) -> (Vec<GpuVertex>, Vec<u32>) {
    let Part { map, keys, indices } = part;
    drop(map);
    let vertices = keys
        .iter()
        .map(|&[v, t, n]| GpuVertex {
            position: g.positions[v as usize],
            normal: if n == NONE {
                [0.0; 3]
            } else {
                g.normals[n as usize]
            },
            // OBJ's v grows upward; the GPU's rows start at the top.
            uv: if t == NONE {
                [0.0; 2]
            } else {
                let [u, v] = g.texcoords[t as usize];
                [u, 1.0 - v]
            },
        })
        .collect();
    (vertices, indices)
}
