//! The ceiling of an RSM as the secondary source (docs/algorithm.md section
//! 5.9, "design B"): each RSM texel would gather the first bounce and re-emit
//! `rho E A`, so the light of bounce 2 and on can only leave, toward the
//! camera's surface, a surface the light sees. This traces the path
//! tracer's own paths (the same samples as `render`) and splits the light of
//! each bounce by whether its re-emitting vertex `y_1` (the surface that
//! sends it on to the surface the camera sees) is seen by a light view:
//! inside one of the RSMs' frusta, facing its light and not occluded from
//! it. What the light does not see, design B cannot carry whatever its
//! gathering.

use super::{ray_offset, PathTraceSettings, Pcg, Shading, SurfacePoint, LAYERS};
use crate::scene::{LightKind, Scene};
use crate::view::LightView;
use bvh::Cull;
use glam::{DVec3, Vec3, Vec3A};
use rayon::prelude::*;

use super::bvh;

/// The indirect irradiance by bounce (bounces 1, 2, 3, 4 on), summed over
/// the pixels and their three channels (W/m^2 times pixels), and the parts
/// of it that design B cannot carry.
#[derive(Clone, Copy, Debug, Default)]
pub struct LightSeenSplit {
    /// Pixels with geometry.
    pub pixels: usize,
    pub by_bounce: [f64; LAYERS],
    /// The light whose re-emitting vertex `y_1` the lights do not see
    /// (bounce 1: the light lit `y_1` and yet it counts as unseen, a check
    /// of the test that should be near 0).
    pub first_unseen: [f64; LAYERS],
    /// The light with any of `y_1 .. y_(k-1)` unseen: what a design B that
    /// iterates bounces among RSM texels cannot carry.
    pub any_unseen: [f64; LAYERS],
}

impl LightSeenSplit {
    fn add(&mut self, o: &LightSeenSplit) {
        self.pixels += o.pixels;
        for k in 0..LAYERS {
            self.by_bounce[k] += o.by_bounce[k];
            self.first_unseen[k] += o.first_unseen[k];
            self.any_unseen[k] += o.any_unseen[k];
        }
    }
}

/// Whether a light view sees the surface point `y`: inside the view's
/// frustum (the RSM's square; a directional box's depth range too), facing
/// its light, and nothing between them (the shadow ray of `direct_from`).
fn seen(sh: &Shading, views: &[LightView], views_origin: DVec3, y: &SurfacePoint) -> bool {
    let world = Vec3::from(y.position).as_dvec3() + sh.origin;
    let at = (world - views_origin).as_vec3();
    views.iter().any(|v| {
        let clip = v.view_proj * at.extend(1.0);
        let inside = clip.w > 0.0
            && clip.x.abs() <= clip.w
            && clip.y.abs() <= clip.w
            && clip.z >= 0.0
            && clip.z <= clip.w;
        if !inside {
            return false;
        }
        let light = &sh.lights[v.light];
        let (l, r) = if light.kind == LightKind::Directional {
            (-Vec3A::from(light.direction).normalize(), f32::INFINITY)
        } else {
            let to = Vec3A::from(light.position) - y.position;
            let r = to.length();
            (to / r, r)
        };
        if y.normal.dot(l).is_nan() || y.normal.dot(l) <= 0.0 {
            return false;
        }
        let offset = ray_offset(y.position);
        sh.bvh
            .intersect(
                y.position + y.normal * offset,
                l,
                offset,
                r * (1.0 - 1e-4),
                true,
                Cull::FrontFaces,
            )
            .is_none()
    })
}

/// Traces `scene` as `super::render` does (same primary rays, seeds and
/// paths) and splits its indirect light by what the light views see.
/// `views` are relative to `views_origin` (the renderer's `render_origin`).
pub fn split(
    scene: &Scene,
    s: &PathTraceSettings,
    views: &[LightView],
    views_origin: DVec3,
) -> LightSeenSplit {
    let sh = Shading::new(scene);
    let at_origin = crate::scene::Camera {
        world_from_camera: glam::Mat4::from_quat(glam::Quat::from_mat4(
            &scene.camera.world_from_camera,
        )),
        ..scene.camera
    };
    let clip_to_world = crate::view::camera_view_proj(&at_origin, s.width, s.height).inverse();
    let (w, h) = (s.width as usize, s.height as usize);
    let scale = std::f64::consts::PI / s.spp as f64;
    (0..h)
        .into_par_iter()
        .map(|y| {
            let mut row = LightSeenSplit::default();
            for x in 0..w {
                let ndc = glam::Vec4::new(
                    2.0 * (x as f32 + 0.5) / s.width as f32 - 1.0,
                    2.0 * (y as f32 + 0.5) / s.height as f32 - 1.0,
                    1.0,
                    1.0,
                );
                let p = clip_to_world * ndc;
                let near = Vec3A::from(p.truncate() / p.w);
                let Some(hit) = sh.trace(near, near.normalize()) else {
                    continue;
                };
                row.pixels += 1;
                let mut rng = Pcg::new(s.seed, (y * w + x) as u64);
                // Per path: whether y_1, and every vertex so far, is seen.
                let (mut first, mut all) = (true, true);
                sh.paths(&hit, s.spp, s.bounces, &mut rng, |k, vertex, light| {
                    let layer = (k as usize).min(LAYERS) - 1;
                    let light = light.as_dvec3().element_sum() * scale;
                    row.by_bounce[layer] += light;
                    if k >= 2 && !first {
                        row.first_unseen[layer] += light;
                    }
                    if k >= 2 && !all {
                        row.any_unseen[layer] += light;
                    }
                    let here = seen(&sh, views, views_origin, vertex);
                    if k == 1 {
                        // Bounce 1 leaves y_1 lit, so seen: a check, ~0.
                        if !here {
                            row.first_unseen[0] += light;
                        }
                        (first, all) = (here, here);
                    } else {
                        all &= here;
                    }
                });
            }
            row
        })
        .reduce(LightSeenSplit::default, |mut a, b| {
            a.add(&b);
            a
        })
}
