//! Fitting the light views (RSMs) to a frame: every light's views, relative
//! to the render origin, directional lights' fitted to the camera's view.

use crate::scene::{FrameState, LightKind};
use crate::view::{light_views, LightView};

/// `bounds` relative to `origin`, widened by a rounding so that they still
/// hold every relative position.
pub(super) fn relative(
    bounds: (glam::Vec3, glam::Vec3),
    origin: glam::DVec3,
) -> (glam::Vec3, glam::Vec3) {
    let (lo, hi) = (bounds.0.as_dvec3() - origin, bounds.1.as_dvec3() - origin);
    let pad = (hi - lo).length() * 1e-6;
    ((lo - pad).as_vec3(), (hi + pad).as_vec3())
}

/// What the light views are fitted to: the scene's world bounds, the
/// render origin, each instance's object-space bounds, the image size.
pub(super) struct ViewFitting<'a> {
    pub(super) bounds: (glam::Vec3, glam::Vec3),
    pub(super) origin: glam::DVec3,
    pub(super) objects: &'a [(glam::Vec3, glam::Vec3)],
    pub(super) size: (u32, u32),
}

/// Every light view of `state`'s lights (`state` relative to the render
/// origin), in light order, relative to the origin; directional lights'
/// RSMs fitted to the view where the scene holds much more
/// (`view::fit_directional`), and their shadow maps fitted to the camera's
/// view at `sun_shadow`'s size (`view::sun_shadow::fit`; `None`: the RSM's
/// square, fixed while the camera moves).
pub(super) fn all_views(
    state: &FrameState,
    f: &ViewFitting,
    rsm: u32,
    sun_shadow: Option<u32>,
) -> Vec<LightView> {
    let bounds = relative(f.bounds, f.origin);
    let directional = state
        .lights
        .iter()
        .any(|l| l.kind == LightKind::Directional);
    let boxes: Vec<(glam::Vec3, glam::Vec3)> = match directional {
        true => f
            .objects
            .iter()
            .zip(&state.instance_transforms)
            .map(|(b, m)| crate::view::transformed_box(m, *b))
            .collect(),
        false => vec![],
    };
    let camera = crate::view::camera_view_proj(&state.camera, f.size.0, f.size.1);
    state
        .lights
        .iter()
        .enumerate()
        .flat_map(|(i, l)| {
            let fit = (l.kind == LightKind::Directional)
                .then(|| crate::view::fit_directional(l.direction, &boxes, camera, bounds))
                .flatten();
            let mut views = light_views(i, l, bounds, fit.as_ref(), rsm);
            // The shadow is fitted within what the RSM covers: a far object
            // that the RSM's fit leaves out must not stretch it either.
            let covered = fit.map_or(bounds, |f| f.footprint);
            for v in views
                .iter_mut()
                .filter(|v| v.kind == LightKind::Directional)
            {
                if let Some(s) = sun_shadow {
                    v.shadow = crate::view::sun_shadow::fit(v, camera, covered, s);
                }
            }
            views
        })
        .collect()
}

/// A mesh's bounds in its own space (a point at the origin for no vertices).
pub(super) fn mesh_bounds(mesh: &crate::scene::Mesh) -> (glam::Vec3, glam::Vec3) {
    let mut it = mesh.vertices.iter().map(|v| glam::Vec3::from(v.position));
    let first = it.next().unwrap_or(glam::Vec3::ZERO);
    it.fold((first, first), |(a, b), p| (a.min(p), b.max(p)))
}
