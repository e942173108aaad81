//! Each mesh's triangles ordered largest first, for pass `voxel-grid`
//! to hand its large triangles to whole workgroups and the rest to one
//! invocation each (`shaders/voxel_grid/voxelize.comp`; docs/algorithm.md
//! section 5, "Voxel visibility").

use crate::scene::Scene;
use glam::{Mat3, Mat4, Vec3};

/// A triangle is large where its bounding box can span more sub-cells than
/// this a side (at most `(LARGE_SUBCELLS + 2)^2` columns otherwise): the
/// large ones are marked by whole workgroups, the others each by one
/// invocation.
const LARGE_SUBCELLS: f32 = 64.0;

/// Every mesh's triangles, largest first, for the voxelization to tell the
/// large from the small each frame with one search per instance: the
/// position of each one's first index (in the scene's index buffer, bound at
/// set 1 binding 2 of `voxel_grid/voxelize.comp`, at the triangle's own place),
/// and per mesh each one's size, its bounding box's diagonal in the mesh's
/// own space, falling.
pub struct TriangleOrder {
    pub first_indices: Vec<u32>,
    pub sizes: Vec<Vec<f32>>,
}

impl TriangleOrder {
    pub fn new(scene: &Scene) -> Self {
        let (mut first_indices, mut sizes) = (vec![], vec![]);
        let mut base = 0u32;
        for mesh in &scene.meshes {
            let size = |t: &[u32]| {
                let p = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
                let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
                (a.max(b).max(c) - a.min(b).min(c)).length()
            };
            let mut order: Vec<(f32, u32)> = mesh
                .indices
                .chunks_exact(3)
                .enumerate()
                .map(|(k, t)| (size(t), base + 3 * k as u32))
                .collect();
            // Largest first; ties in the mesh's order (a stable sort).
            order.sort_by(|x, y| y.0.total_cmp(&x.0));
            first_indices.extend(order.iter().map(|o| o.1));
            sizes.push(order.iter().map(|o| o.0).collect());
            base += mesh.indices.len() as u32;
        }
        TriangleOrder {
            first_indices,
            sizes,
        }
    }

    /// How many of mesh `mesh`'s triangles are large under the transform
    /// `world_from_object` in a grid of `per` sub-cells per unit of length:
    /// those whose size, scaled by the transform's Frobenius norm (at least
    /// its largest stretch), exceeds `LARGE_SUBCELLS` sub-cells.
    pub fn large(&self, mesh: usize, world_from_object: &Mat4, per: f32) -> u32 {
        let m = Mat3::from_mat4(*world_from_object);
        let stretch =
            (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared())
                .sqrt();
        // NaN or infinite transforms are refused when a frame is posed; a
        // size that cannot be bounded counts as large.
        self.sizes[mesh].partition_point(|&d| {
            let x = d * stretch * per;
            x > LARGE_SUBCELLS || x.is_nan()
        }) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::GpuVertex;

    #[test]
    fn each_meshs_triangles_come_largest_first_and_scale_with_their_instance() {
        let mut scene = crate::scene::cornell::cornell_box();
        scene.meshes.clear();
        scene.instances.clear();
        let vertex = |x: f32, y: f32| GpuVertex {
            position: [x, y, 0.0],
            normal: [0.0, 0.0, 1.0],
            uv: [0.0, 0.0],
        };
        // Two meshes: triangles of sides 1, 3, 2 (diagonals sqrt 2 times
        // that), then one of side 5.
        let tri = |s: f32| [vertex(0.0, 0.0), vertex(s, 0.0), vertex(0.0, s)];
        let first: Vec<GpuVertex> = [1.0, 3.0, 2.0].into_iter().flat_map(tri).collect();
        scene.add_mesh("first", first, (0..9).collect(), 0);
        scene.add_mesh("second", tri(5.0).to_vec(), vec![0, 1, 2], 0);
        let order = TriangleOrder::new(&scene);
        // Positions of first indices: the second mesh's start at 9.
        assert_eq!(order.first_indices, vec![3, 6, 0, 9]);
        let root2 = 2f32.sqrt();
        assert_eq!(order.sizes[0], vec![3.0 * root2, 2.0 * root2, root2]);
        // Large: over LARGE_SUBCELLS sub-cells at `per` sub-cells a unit,
        // scaled by the transform's Frobenius norm (sqrt 3 for the identity).
        let per = LARGE_SUBCELLS / (2.5 * root2 * 3f32.sqrt());
        assert_eq!(order.large(0, &Mat4::IDENTITY, per), 1);
        assert_eq!(order.large(0, &Mat4::from_scale(Vec3::splat(2.0)), per), 2);
        assert_eq!(order.large(0, &Mat4::from_scale(Vec3::splat(3.0)), per), 3);
        assert_eq!(order.large(0, &Mat4::from_scale(Vec3::splat(0.1)), per), 0);
        assert_eq!(order.large(1, &Mat4::IDENTITY, per), 1);
    }
}
