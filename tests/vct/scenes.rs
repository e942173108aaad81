//! The scenes of tests/vct.rs. The closed sphere is tests/bounces.rs's
//! (docs/algorithm.md section 5.4, "Bounces"), the one scene whose first
//! bounce is known exactly.
use super::common::spot;
use glam::Vec3;
use isr::scene::{Camera, GpuVertex, Scene};

/// The inside of a sphere of radius 1 about the origin: an icosahedron
/// subdivided `level` times (20 * 4^level triangles, every vertex on the
/// sphere), each triangle facing the centre (counter-clockwise seen from
/// it) with its own vertices and the facet's normal, so that the surface
/// shaded is the polyhedron the rays meet. Returns the vertices, indices and
/// the polyhedron's own area.
pub fn inside_of_a_sphere(level: u32) -> (Vec<GpuVertex>, Vec<u32>, f64) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let corners = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .map(|c| Vec3::from(c).normalize());
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut triangles: Vec<[Vec3; 3]> = faces.iter().map(|f| f.map(|k| corners[k])).collect();
    for _ in 0..level {
        // Each edge's midpoint, pushed out to the sphere: (a + b) is the
        // same sum from either triangle of the edge, so the mesh stays closed.
        let mid = |a: Vec3, b: Vec3| ((a + b) * 0.5).normalize();
        triangles = triangles
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    let (mut vertices, mut indices, mut area) = (vec![], vec![], 0.0);
    for [a, b, c] in triangles {
        let cross = (b - a).cross(c - a);
        // Counter-clockwise from the centre: the normal points at it.
        let (b, c) = if cross.dot(a + b + c) > 0.0 {
            (c, b)
        } else {
            (b, c)
        };
        let normal = (b - a).cross(c - a).normalize();
        let (a64, b64, c64) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        area += 0.5 * (b64 - a64).cross(c64 - a64).length();
        for p in [a, b, c] {
            indices.push(vertices.len() as u32);
            vertices.push(GpuVertex {
                position: p.to_array(),
                normal: normal.to_array(),
                uv: [0.0; 2],
            });
        }
    }
    (vertices, indices, area)
}

/// The spot at the centre of the sphere: it lights the lower cap.
const INTENSITY: f32 = 3.0;
const INNER_DEG: f32 = 45.0;
const OUTER_DEG: f32 = 60.0;

/// The power the spot sends into the sphere, all of which lands on its
/// inside: `Phi = integral of I(w) dw = 2 pi I integral of a(c) dc` over
/// `c = cos(theta)`, with KHR_lights_punctual's falloff `a(c) = t^2`,
/// `t = (c - cos outer) / (cos inner - cos outer)` clamped to [0, 1]: 1 on
/// `[cos inner, 1]`, and `(cos inner - cos outer) / 3` for the ramp.
pub fn spot_power() -> f64 {
    let (ci, co) = (
        (INNER_DEG as f64).to_radians().cos(),
        (OUTER_DEG as f64).to_radians().cos(),
    );
    2.0 * std::f64::consts::PI * INTENSITY as f64 * ((1.0 - ci) + (ci - co) / 3.0)
}

/// The sphere of albedo `rho` (per channel), lit from its centre, seen from
/// inside by a camera that sees both the lit cap and the unlit wall.
pub fn sphere(rho: Vec3, level: u32) -> (Scene, f64) {
    let light = spot(Vec3::ZERO, -Vec3::Y, INTENSITY, INNER_DEG, OUTER_DEG);
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.4, 0.0),
        Vec3::new(1.0, -0.6, 0.0),
        Vec3::Y,
        90f32.to_radians(),
        0.01,
    );
    let mut s = Scene::empty("sphere", light, camera);
    let m = s.add_material("wall", rho);
    let (v, i, area) = inside_of_a_sphere(level);
    s.add_mesh("sphere", v, i, m);
    (s, area)
}
