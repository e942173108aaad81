//! A directional light's shadow map fitted to what the camera sees
//! (docs/algorithm.md section 2.2): the square, perpendicular to the light,
//! around the view frustum's intersection with the scene's bounds, rather
//! than around the whole scene (the RSM's square, which the indirect light
//! needs whole). Its side is the RSM's halved a whole number of times and
//! its centre snapped to whole shadow texels of a grid fixed to the scene,
//! so the texels stay put on the scene as the camera moves (no shimmer)
//! and change size only when the view's extent crosses a power of two.

use super::{directional_frame, LightView, ShadowFrustum};
use glam::{Mat4, Vec2, Vec3, Vec4};

/// How many halvings of the RSM's side the shadow square may take: 2^-16
/// of the scene is far below any view's extent at any shadow size.
const MAX_HALVINGS: i32 = 16;

/// Texels of margin on each side of the fitted square: the PCF taps of a
/// receiver on the view's edge reach 2 texels beyond it (docs/algorithm.md
/// section 2.2: 3x3 taps one texel apart, each a 2x2 compare).
const MARGIN_TEXELS: f32 = 4.0;

/// The shadow frustum of directional view `v` (its RSM fitted to `bounds`,
/// the scene's, in the same frame) for a camera of `camera_view_proj`
/// (reversed-Z, infinite far), at `s` x `s` texels. The RSM's own square
/// where the view holds no part of the bounds. The depth range stays the
/// RSM's: every caster toward the light is in it.
pub fn fit(v: &LightView, camera_view_proj: Mat4, bounds: (Vec3, Vec3), s: u32) -> ShadowFrustum {
    let rsm = ShadowFrustum::of_rsm(v.view_proj, v.half_extent);
    let rot = directional_frame(v.direction);
    let centre = rot.transform_point3(v.position);
    let h = v.half_extent;
    let Some((lo, hi)) = seen(camera_view_proj, bounds, &rot) else {
        return rsm;
    };
    // Within the RSM's square, which covers every receiver the frame can light.
    let (lo, hi) = (lo.max(centre.truncate() - h), hi.min(centre.truncate() + h));
    if !(lo.cmplt(hi).all()) {
        return rsm;
    }
    let s = s as f32;
    let need = 0.5 * (hi - lo).max_element() * (1.0 + 2.0 * MARGIN_TEXELS / s);
    let halvings = ((h / need).log2().floor() as i32).clamp(0, MAX_HALVINGS);
    let half = h / 2f32.powi(halvings);
    let texel = 2.0 * half / s;
    // Snapped to whole texels from a corner of the scene's bounds: a grid
    // fixed to the scene (and moved with it), whatever the camera does.
    let anchor = rot.transform_point3(bounds.0).truncate();
    let mid = 0.5 * (lo + hi);
    let snapped = anchor + ((mid - anchor) / texel).round() * texel;
    // The RSM's depth range: the eye on its near plane.
    let eye = rot.inverse().transform_point3(snapped.extend(centre.z));
    let up = if v.direction.dot(Vec3::Y).abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let view = Mat4::look_to_rh(eye, v.direction, up);
    let ortho = Mat4::orthographic_rh(-half, half, -half, half, v.depth_range, 0.0);
    ShadowFrustum {
        view_proj: Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0)) * ortho * view,
        half_extent: half,
    }
}

/// The light-frame (`rot`) x, y bounds of the part of `bounds` the camera
/// can see: the corners of the convex intersection of the view frustum
/// (cut at the bounds' farthest depth) with the box, each the corner of one
/// inside the other or an edge of one through a face of the other. `None`
/// where the two do not meet.
fn seen(camera_view_proj: Mat4, bounds: (Vec3, Vec3), rot: &Mat4) -> Option<(Vec2, Vec2)> {
    let (lo, hi) = bounds;
    let box_corners: [Vec3; 8] = std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    });
    // Reversed-Z with an infinite far plane: NDC depth is near / depth, so
    // the farthest corner in front has the smallest positive NDC depth.
    let far = box_corners
        .iter()
        .map(|c| camera_view_proj * c.extend(1.0))
        .filter(|c| c.w > 0.0)
        .map(|c| c.z / c.w)
        .fold(f32::INFINITY, f32::min);
    if !(far.is_finite() && far > 0.0) {
        return None;
    }
    // The frustum's planes as linear functions of clip coordinates, >= 0 inside.
    let planes = [
        Vec4::new(1.0, 0.0, 0.0, 1.0),
        Vec4::new(-1.0, 0.0, 0.0, 1.0),
        Vec4::new(0.0, 1.0, 0.0, 1.0),
        Vec4::new(0.0, -1.0, 0.0, 1.0),
        Vec4::new(0.0, 0.0, -1.0, 1.0),
        Vec4::new(0.0, 0.0, 1.0, -far),
    ];
    let clip = |p: Vec3| camera_view_proj * p.extend(1.0);
    let slack = 1e-4;
    let in_frustum = |p: Vec3| {
        let c = clip(p);
        planes.iter().all(|f| f.dot(c) >= -slack * c.w.abs())
    };
    let size = (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
    let in_box =
        |p: Vec3| (p - lo).cmpge(-slack * size).all() && (hi - p).cmpge(-slack * size).all();
    let inverse = camera_view_proj.inverse();
    let frustum_corners: [Vec3; 8] = std::array::from_fn(|i| {
        let ndc = Vec4::new(
            if i & 1 == 0 { -1.0 } else { 1.0 },
            if i & 2 == 0 { -1.0 } else { 1.0 },
            if i & 4 == 0 { 1.0 } else { far },
            1.0,
        );
        let w = inverse * ndc;
        w.truncate() / w.w
    });
    // The 12 edges of a box-like corner list (corner i, bit k flipped).
    let edges = |c: &[Vec3; 8]| {
        let mut e = Vec::with_capacity(12);
        for i in 0..8 {
            for k in [1, 2, 4] {
                if i & k == 0 {
                    e.push((c[i], c[i | k]));
                }
            }
        }
        e
    };
    let mut points: Vec<Vec3> = Vec::new();
    points.extend(box_corners.iter().copied().filter(|&p| in_frustum(p)));
    points.extend(frustum_corners.iter().copied().filter(|&p| in_box(p)));
    // Box edges through the frustum's planes.
    for (a, b) in edges(&box_corners) {
        let (ca, cb) = (clip(a), clip(b));
        for f in &planes {
            let (da, db) = (f.dot(ca), f.dot(cb));
            if (da < 0.0) != (db < 0.0) {
                let p = a + (b - a) * (da / (da - db));
                if in_frustum(p) {
                    points.push(p);
                }
            }
        }
    }
    // Frustum edges through the box's faces.
    for (a, b) in edges(&frustum_corners) {
        for axis in 0..3 {
            for plane in [lo[axis], hi[axis]] {
                let (da, db) = (a[axis] - plane, b[axis] - plane);
                if (da < 0.0) != (db < 0.0) {
                    let p = a + (b - a) * (da / (da - db));
                    if in_box(p) {
                        points.push(p);
                    }
                }
            }
        }
    }
    let light: Vec<Vec2> = points
        .iter()
        .map(|&p| rot.transform_point3(p).truncate())
        .filter(|p| p.is_finite())
        .collect();
    let first = *light.first()?;
    Some(
        light
            .iter()
            .fold((first, first), |(a, b), &p| (a.min(p), b.max(p))),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Light, LightKind};

    fn sun() -> Light {
        Light {
            kind: LightKind::Directional,
            position: Vec3::ZERO,
            direction: Vec3::new(1.0, -0.5, 0.6).normalize(),
            color: Vec3::ONE,
            intensity: 3.0,
            inner_cone: 0.0,
            outer_cone: std::f32::consts::FRAC_PI_2,
            range: None,
        }
    }

    fn camera_at(eye: Vec3) -> Mat4 {
        let c = Camera::look_at(
            eye,
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::Y,
            40f32.to_radians(),
            0.05,
        );
        crate::view::camera_view_proj(&c, 256, 256)
    }

    /// A close view of a 100 m ground gets a shadow square far smaller than
    /// the RSM's, and as the camera slides its texel grid stays put: every
    /// frame's texel corners lie on one grid (a whole number of texels
    /// between any two frames' origins).
    #[test]
    fn a_close_view_gets_a_small_square_on_a_grid_fixed_to_the_scene() {
        let bounds = (Vec3::new(-50.0, 0.0, -50.0), Vec3::new(50.0, 2.0, 50.0));
        let v = &crate::view::light_views(0, &sun(), bounds, None, 512)[0];
        let s = 1024;
        let mut first: Option<ShadowFrustum> = None;
        for k in 0..12 {
            let eye = Vec3::new(3.0 + 0.173 * k as f32, 4.0, 5.0);
            let f = fit(v, camera_at(eye), bounds, s);
            // The view spans about 15 m of the 141 m the RSM's square spans.
            assert!(
                f.half_extent * 4.0 <= v.half_extent,
                "{} of {}",
                f.half_extent,
                v.half_extent
            );
            let Some(f0) = first else {
                first = Some(f);
                continue;
            };
            assert_eq!(f.half_extent, f0.half_extent, "frame {k}");
            // Where the scene's origin falls, in texels of each frame: the
            // fractional parts agree to within float error.
            let texel = |m: Mat4| {
                let c = m * Vec3::ZERO.extend(1.0);
                (c.truncate().truncate() * 0.5 + 0.5) * s as f32
            };
            let d = texel(f.view_proj) - texel(f0.view_proj);
            let off = (d - d.round()).abs().max_element();
            assert!(off < 1e-2, "frame {k}: the grid moved {off} texels");
        }
    }

    /// A camera that sees the whole scene keeps the RSM's square.
    #[test]
    fn a_view_of_everything_keeps_the_rsm_square() {
        let bounds = (Vec3::splat(-1.0), Vec3::splat(1.0));
        let v = &crate::view::light_views(0, &sun(), bounds, None, 512)[0];
        let f = fit(v, camera_at(Vec3::new(6.0, 5.0, 7.0)), bounds, 1024);
        assert_eq!(f.half_extent, v.half_extent);
    }
}
