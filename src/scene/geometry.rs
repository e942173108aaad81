//! Meshes built by code (quads, boxes) and normals for meshes without them.

use super::GpuVertex;
use glam::{Vec2, Vec3};

/// Vertices and indices of a planar quad given counter-clockwise from its front.
pub fn quad(c: [Vec3; 4]) -> (Vec<GpuVertex>, Vec<u32>) {
    let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize();
    let uvs = [
        Vec2::new(0.0, 1.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(0.0, 0.0),
    ];
    let vertices = c
        .iter()
        .zip(uvs)
        .map(|(p, uv)| GpuVertex {
            position: p.to_array(),
            normal: n.to_array(),
            uv: uv.to_array(),
        })
        .collect();
    (vertices, vec![0, 1, 2, 0, 2, 3])
}

/// A closed box with outward faces: `center`, full `size`, turned by `yaw` radians about +Y.
pub fn cuboid(center: Vec3, size: Vec3, yaw: f32) -> (Vec<GpuVertex>, Vec<u32>) {
    let rot = glam::Quat::from_rotation_y(yaw);
    let h = size * 0.5;
    let corner = |x: f32, y: f32, z: f32| center + rot * Vec3::new(x * h.x, y * h.y, z * h.z);
    // Each face counter-clockwise seen from outside.
    let faces = [
        [
            corner(-1., -1., 1.),
            corner(1., -1., 1.),
            corner(1., 1., 1.),
            corner(-1., 1., 1.),
        ], // +z
        [
            corner(1., -1., -1.),
            corner(-1., -1., -1.),
            corner(-1., 1., -1.),
            corner(1., 1., -1.),
        ], // -z
        [
            corner(1., -1., 1.),
            corner(1., -1., -1.),
            corner(1., 1., -1.),
            corner(1., 1., 1.),
        ], // +x
        [
            corner(-1., -1., -1.),
            corner(-1., -1., 1.),
            corner(-1., 1., 1.),
            corner(-1., 1., -1.),
        ], // -x
        [
            corner(-1., 1., 1.),
            corner(1., 1., 1.),
            corner(1., 1., -1.),
            corner(-1., 1., -1.),
        ], // +y
        [
            corner(-1., -1., -1.),
            corner(1., -1., -1.),
            corner(1., -1., 1.),
            corner(-1., -1., 1.),
        ], // -y
    ];
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for f in faces {
        let (v, i) = quad(f);
        let base = vertices.len() as u32;
        vertices.extend(v);
        indices.extend(i.into_iter().map(|i| i + base));
    }
    (vertices, indices)
}

/// Face normals accumulated per vertex, for primitives without NORMAL.
/// The factor that scales `vertices` to about unit size (1 when they are
/// all at the origin or not finite), for cross products of their edges: at
/// 1e18 m one (1e36) would overflow when normalised. One scale for the
/// whole mesh keeps the area weights' ratios.
fn unit_scale(vertices: &[GpuVertex]) -> f32 {
    let extent = vertices
        .iter()
        .flat_map(|v| v.position)
        .fold(0f32, |m, c| m.max(c.abs()));
    if extent > 0.0 && extent.is_finite() {
        1.0 / extent
    } else {
        1.0
    }
}

pub fn compute_normals(vertices: &mut [GpuVertex], indices: &[u32]) {
    // Positions scaled to about unit size first (`unit_scale`).
    let scale = unit_scale(vertices);
    let mut acc = vec![Vec3::ZERO; vertices.len()];
    for t in indices.chunks_exact(3) {
        let p = |k: usize| Vec3::from(vertices[t[k] as usize].position) * scale;
        // Area-weighted: the cross product's length is twice the area.
        let n = (p(1) - p(0)).cross(p(2) - p(0));
        for &k in t {
            acc[k as usize] += n;
        }
    }
    for (v, n) in vertices.iter_mut().zip(acc) {
        v.normal = n.normalize_or(Vec3::Y).to_array();
    }
}

/// `v` as a unit vector, scaled first so that no square overflows or
/// underflows in f32 (`[0, 1e30, 0]` and `[0, 1e-30, 0]` are +Y, where
/// `normalize` gives NaN or nothing); `None` for zero or non-finite.
pub fn direction(v: Vec3) -> Option<Vec3> {
    let m = v.abs().max_element();
    if !(m > 0.0 && m.is_finite()) {
        return None;
    }
    (v / m).try_normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_faces_point_outward() {
        let center = Vec3::new(0.3, 0.5, -0.2);
        let (v, i) = cuboid(center, Vec3::new(0.6, 1.0, 0.4), 0.7);
        for t in i.chunks_exact(3) {
            let p = |k: usize| Vec3::from(v[t[k] as usize].position);
            let n = (p(1) - p(0)).cross(p(2) - p(0));
            assert!(n.dot(p(0) - center) > 0.0, "face winding points inward");
            assert!(n
                .normalize()
                .abs_diff_eq(Vec3::from(v[t[0] as usize].normal), 1e-5));
        }
    }

    #[test]
    fn directions_of_any_length() {
        for v in [
            Vec3::new(0.0, 1e30, 0.0),
            Vec3::new(0.0, 1e-30, 0.0),
            Vec3::new(0.0, 1e-44, 0.0),
        ] {
            assert_eq!(direction(v), Some(Vec3::Y), "{v}");
        }
        let d = direction(Vec3::new(1e30, -1e30, 0.0)).unwrap();
        assert!(d.abs_diff_eq(Vec3::new(1.0, -1.0, 0.0).normalize(), 1e-6));
        assert_eq!(direction(Vec3::ZERO), None);
        assert_eq!(direction(Vec3::new(f32::INFINITY, 0.0, 0.0)), None);
    }

    #[test]
    fn computed_normals_of_a_flat_quad_are_its_normal() {
        let (mut v, i) = quad([Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, -1.0), -Vec3::Z]);
        for x in &mut v {
            x.normal = [0.0; 3];
        }
        compute_normals(&mut v, &i);
        assert!(v
            .iter()
            .all(|x| Vec3::from(x.normal).abs_diff_eq(Vec3::Y, 1e-6)));
    }
}
