//! The voxel grid's voxelization (pass `voxel-grid`,
//! `shaders/voxel_grid/voxelize.comp`; docs/algorithm.md section 5, "Voxel
//! visibility") against a separating-axis test written here, on triangles
//! of every size and orientation: the large ones that whole workgroups
//! share, the small ones that one invocation marks, an instance stretched
//! so that its small triangles become large, axis-aligned ones whose inner
//! columns skip the per-sub-cell test, and one without area.
mod common;

use common::*;
use glam::{DVec3, Mat4, Quat, Vec3};
use isr::scene::{Camera, GpuVertex, Scene};
use isr::voxel_grid::{GRID, SUBCELLS};

/// A fixed pseudo-random sequence in [0, 1) (64-bit LCG).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn point(&mut self, c: Vec3, half: f32) -> Vec3 {
        c + Vec3::new(self.next(), self.next(), self.next()) * 2.0 * half - half
    }
}

/// A mesh of `n` triangles, each with its corners within `half` of a centre
/// drawn in the unit cube.
fn triangles(rng: &mut Lcg, n: usize, half: f32) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let c = rng.point(Vec3::splat(0.5), 0.5);
            [rng.point(c, half), rng.point(c, half), rng.point(c, half)]
        })
        .collect()
}

fn add(s: &mut Scene, name: &str, tris: &[[Vec3; 3]], transform: Mat4) {
    let m = s.add_material(name, Vec3::splat(0.5));
    let vertices = tris
        .iter()
        .flatten()
        .map(|p| GpuVertex {
            position: p.to_array(),
            normal: [0.0, 1.0, 0.0],
            uv: [0.0, 0.0],
        })
        .collect();
    let indices = (0..3 * tris.len() as u32).collect();
    s.add_mesh(name, vertices, indices, m);
    s.instances.last_mut().unwrap().world_from_object = transform;
}

/// Whether the triangle (corners relative to a box's centre) overlaps the
/// box of half side `h`: the 13 axes of the separating-axis test.
fn overlaps(v: [DVec3; 3], h: f64) -> bool {
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let n = e[0].cross(e[1]);
    let mut axes = vec![DVec3::X, DVec3::Y, DVec3::Z, n];
    for e in e {
        axes.extend([DVec3::X, DVec3::Y, DVec3::Z].map(|a| e.cross(a)));
    }
    axes.iter().all(|a| {
        let p = v.map(|p| a.dot(p));
        let r = h * (a.x.abs() + a.y.abs() + a.z.abs());
        let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        !(lo > r || hi < -r)
    })
}

#[test]
fn the_voxelization_marks_the_sub_cells_each_triangle_touches() {
    let mut rng = Lcg(25);
    let light = spot(Vec3::new(0.5, 2.0, 0.5), Vec3::splat(0.5), 10.0, 30.0, 40.0);
    let camera = Camera::look_at(
        Vec3::new(0.5, 0.5, 3.0),
        Vec3::splat(0.5),
        Vec3::Y,
        50f32.to_radians(),
        0.1,
    );
    let mut s = Scene::empty("triangles", light, camera);
    // Across the cube (whole workgroups), a few sub-cells wide (one
    // invocation), under a sub-cell, and axis-aligned quads.
    let mut large = triangles(&mut rng, 6, 0.5);
    // Across the whole cube: more columns than one invocation could mark
    // within lavapipe's loop limit.
    large.extend([
        [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.1),
            Vec3::new(0.0, 1.0, 1.0),
        ],
        [
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 0.9, 0.0),
            Vec3::new(1.0, 0.0, 1.0),
        ],
    ]);
    add(&mut s, "large", &large, Mat4::IDENTITY);
    add(
        &mut s,
        "medium",
        &triangles(&mut rng, 60, 0.04),
        Mat4::IDENTITY,
    );
    add(
        &mut s,
        "tiny",
        &triangles(&mut rng, 60, 0.002),
        Mat4::IDENTITY,
    );
    let wall = |x: f32| {
        let (a, b, c, d) = (
            Vec3::new(x, 0.1, 0.1),
            Vec3::new(x, 0.9, 0.1),
            Vec3::new(x, 0.9, 0.8),
            Vec3::new(x, 0.1, 0.8),
        );
        [[a, b, c], [a, c, d]]
    };
    add(
        &mut s,
        "walls",
        &[wall(0.3), wall(0.61)].concat(),
        Mat4::IDENTITY,
    );
    // Triangles small in their mesh (a fiftieth of the cube), stretched 40
    // times by their instance: large in the grid, too large for one
    // invocation.
    let stretched = Mat4::from_scale_rotation_translation(
        Vec3::splat(40.0),
        Quat::from_euler(glam::EulerRot::XYZ, 0.3, 0.7, 0.2),
        Vec3::splat(0.5),
    );
    add(
        &mut s,
        "stretched",
        &triangles(&mut rng, 4, 0.4)
            .iter()
            .chain(&[[
                Vec3::ZERO,
                Vec3::new(1.0, 0.0, 0.5),
                Vec3::new(0.0, 1.0, 1.0),
            ]])
            .map(|t| t.map(|p| (p - 0.5) * 0.02))
            .collect::<Vec<_>>(),
        stretched,
    );
    let degenerate = [[Vec3::splat(0.2), Vec3::splat(0.5), Vec3::splat(0.8)]];
    add(&mut s, "degenerate", &degenerate, Mat4::IDENTITY);

    let gpu = validating_gpu();
    let (n, sub) = (64u32, 4u32);
    let settings = voxels(sized("reference", 16, 16, 16), n);
    assert_eq!((GRID.get(&settings), SUBCELLS.get(&settings)), (n, sub));
    let (words, cube, origin) = rendered_grid(&gpu, &s, &settings);

    // Sub-cells of the whole grid: `side` a side, each `size` long.
    let side = (n * sub) as usize;
    let size = cube[3] as f64 / sub as f64;
    let corner = DVec3::new(cube[0] as f64, cube[1] as f64, cube[2] as f64) + origin;
    let set = |q: [usize; 3]| {
        let (c, o) = (q.map(|x| x / sub as usize), q.map(|x| x % sub as usize));
        let cell = c[0] + n as usize * (c[1] + n as usize * c[2]);
        let bit = o[0] + sub as usize * (o[1] + sub as usize * o[2]);
        words[2 * cell + bit / 32] >> (bit % 32) & 1 == 1
    };
    // Each triangle (with area) must mark every sub-cell it passes through,
    // however its invocations share it; and no sub-cell may be marked that
    // none comes within a hundredth of a sub-cell of.
    let mut near = vec![false; side * side * side];
    let (mut must, mut missed) = (0usize, vec![]);
    for inst in &s.instances {
        let mesh = &s.meshes[inst.mesh];
        for t in mesh.indices.chunks_exact(3) {
            let v = [t[0], t[1], t[2]].map(|i| {
                let p = inst
                    .world_from_object
                    .transform_point3(Vec3::from(mesh.vertices[i as usize].position));
                (p.as_dvec3() - corner) / size
            });
            let area = (v[1] - v[0]).cross(v[2] - v[0]).length() > 1e-9;
            let lo = v[0].min(v[1]).min(v[2]).floor() - 1.0;
            let hi = v[0].max(v[1]).max(v[2]).floor() + 1.0;
            let range =
                |a: usize| (lo[a].max(0.0) as usize)..=(hi[a].min(side as f64 - 1.0) as usize);
            for z in range(2) {
                for y in range(1) {
                    for x in range(0) {
                        let centre = DVec3::new(x as f64, y as f64, z as f64) + 0.5;
                        let rel = v.map(|p| p - centre);
                        if overlaps(rel, 0.51) {
                            near[x + side * (y + side * z)] = true;
                        }
                        if area && overlaps(rel, 0.499) {
                            must += 1;
                            if !set([x, y, z]) {
                                missed.push((mesh.name.clone(), [x, y, z]));
                            }
                        }
                    }
                }
            }
        }
    }
    let mut stray = 0;
    for z in 0..side {
        for y in 0..side {
            for x in 0..side {
                stray += (set([x, y, z]) && !near[x + side * (y + side * z)]) as usize;
            }
        }
    }
    println!(
        "{must} sub-cells crossed, {} missed, {stray} marked with no triangle near",
        missed.len()
    );
    assert!(must > 10_000, "the triangles cross {must} sub-cells");
    assert!(
        missed.is_empty(),
        "{} of {must} missed, e.g. {:?}",
        missed.len(),
        &missed[..missed.len().min(5)]
    );
    assert_eq!(stray, 0, "sub-cells marked with no triangle near");
}
