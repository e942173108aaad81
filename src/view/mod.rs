//! Camera and light projections, shared by the GPU frame (`frame::uniforms`)
//! and the CPU path tracer, so both see the scene from the same places.

pub mod sun_shadow;

use crate::scene::{Camera, Light, LightKind, SpotLight};
use glam::{Mat4, Vec3};

/// What the G-buffer normal's 16-bit w holds of the view depth: a power of
/// two that maps the farthest the scene reaches from the camera at `eye` to
/// at most 2^15, so that no depth overflows half floats (65504) and depths
/// down to 2^-29 of that reach stay normal numbers (relative precision 2^-11
/// at any scale). A power of two keeps scaled scenes' depths exact multiples.
pub fn normal_depth_scale(eye: Vec3, (lo, hi): (Vec3, Vec3)) -> f32 {
    let far = (lo - eye).abs().max((hi - eye).abs()).length();
    if !(far.is_finite() && far > 0.0) {
        return 1.0;
    }
    2f32.powi(15 - far.log2().ceil() as i32)
}

/// The largest RSM half field of view; wider cones are cut (a warning says so).
pub const MAX_RSM_HALF_FOV: f32 = 80.0 * std::f32::consts::PI / 180.0;

/// World -> clip for Vulkan: y flipped (framebuffer y points down), reversed-Z
/// with an infinite far plane (depth 1 at `near`, 0 at infinity).
pub fn projection(fov_y: f32, aspect: f32, near: f32) -> Mat4 {
    Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0))
        * Mat4::perspective_infinite_reverse_rh(fov_y, aspect, near)
}

/// World -> camera clip for an image of `width` x `height`.
pub fn camera_view_proj(camera: &Camera, width: u32, height: u32) -> Mat4 {
    let view = camera.world_from_camera.inverse();
    projection(camera.yfov, width as f32 / height as f32, camera.znear) * view
}

/// The RSM's half field of view: the spot's outer cone, at most `MAX_RSM_HALF_FOV`.
pub fn rsm_half_fov(light: &SpotLight) -> f32 {
    light.outer_cone.min(MAX_RSM_HALF_FOV)
}

/// World -> RSM clip: a square frustum around the spot's outer cone, with
/// the near plane `near` (`rsm_near`).
pub fn light_view_proj(light: &SpotLight, near: f32) -> Mat4 {
    let up = if light.direction.dot(Vec3::Y).abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let view = Mat4::look_to_rh(light.position, light.direction, up);
    projection(2.0 * rsm_half_fov(light), 1.0, near) * view
}

/// The near plane of a perspective RSM at `eye` for a scene within
/// `bounds`: 1e-9 of the farthest the scene reaches from the light.
/// Depth is reversed-Z in 32-bit floats, `near / distance`, whose relative
/// precision does not depend on `near`; so `near` only has to be below
/// whatever the light sees and large enough that `near / distance` never
/// underflows. Sizing it from the scene's extent instead put it beyond a
/// 2 m box once one object stood 50 km away (issue 29), and at 1e-6 m
/// beyond a box scaled to 2e-7 m; 1e-6 of the reach still clipped a point
/// light's walls 1 m away when an object stood 500 km off.
pub fn rsm_near(eye: Vec3, (lo, hi): (Vec3, Vec3)) -> f32 {
    let far = (lo - eye).abs().max((hi - eye).abs()).length();
    (far * 1e-9).max(f32::MIN_POSITIVE * 1e8)
}

/// The axis of cube face `f` (0..5: +x, -x, +y, -y, +z, -z).
pub fn cube_face_axis(f: usize) -> Vec3 {
    let mut a = Vec3::ZERO;
    a[f / 2] = if f.is_multiple_of(2) { 1.0 } else { -1.0 };
    a
}

/// One RSM a frame renders: a spot light, one cube face of a point light, or
/// a directional light (docs/algorithm.md section 2.4). Each has its own frame
/// set, RSM pass, light tree and indirect passes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightView {
    /// Index into the scene's lights.
    pub light: usize,
    pub kind: LightKind,
    /// The cube face (0..5) of a point light.
    pub face: Option<usize>,
    /// World -> RSM clip (reversed-Z; infinite far for perspective views).
    pub view_proj: Mat4,
    /// Where the RSM looks from (the light; for a directional light the
    /// centre of the near face of its box) and along.
    pub position: Vec3,
    pub direction: Vec3,
    /// Perspective: tan of the half field of view. Orthographic: half the
    /// side of the square it covers (m).
    pub half_extent: f32,
    /// Orthographic: the depth range it covers (m); 0 for perspective views.
    pub depth_range: f32,
    /// A point light's six faces' `view_proj` (every face view holds all
    /// six: the cube is rendered in one layered draw); zero otherwise.
    pub cube: [Mat4; 6],
    /// The direct light's shadow map (docs/algorithm.md section 2.2): the
    /// RSM's frustum for spot and point lights; a directional light's is
    /// fitted to the camera's view (`sun_shadow::fit`).
    pub shadow: ShadowFrustum,
}

/// Where a light view's shadow map looks: world -> shadow clip and, as
/// `LightView::half_extent`, tan of its half field of view (perspective)
/// or half its side (m, orthographic). An orthographic shadow map has the
/// RSM's depth range, so depth biases mean the same in both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowFrustum {
    pub view_proj: Mat4,
    pub half_extent: f32,
}

impl ShadowFrustum {
    /// The RSM's own frustum.
    pub fn of_rsm(view_proj: Mat4, half_extent: f32) -> Self {
        Self {
            view_proj,
            half_extent,
        }
    }
}

impl LightView {
    /// A short name for timings: the light's index, and the face of a cube.
    pub fn label(&self) -> String {
        const FACES: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];
        match self.face {
            Some(f) => format!("{}{}", self.light, FACES[f]),
            None => self.light.to_string(),
        }
    }
}

/// The RSMs of `light`: one for a spot or directional light, six for a point
/// light. Positions (the light's, `bounds`, the scene's) may be relative to
/// any origin (the renderer's is `scene::render_origin`). `bounds` fit the
/// directional light's box and place the perspective near plane;
/// `rsm_resolution` snaps the box to texels of a grid fixed to the scene.
pub fn light_views(
    index: usize,
    light: &Light,
    bounds: (Vec3, Vec3),
    fit: Option<&DirectionalFit>,
    rsm_resolution: u32,
) -> Vec<LightView> {
    let near = rsm_near(light.position, bounds);
    let up_for = |d: Vec3| {
        if d.dot(Vec3::Y).abs() > 0.99 {
            Vec3::X
        } else {
            Vec3::Y
        }
    };
    match light.kind {
        LightKind::Spot => vec![LightView {
            light: index,
            kind: LightKind::Spot,
            face: None,
            view_proj: light_view_proj(light, near),
            position: light.position,
            direction: light.direction,
            half_extent: rsm_half_fov(light).tan(),
            depth_range: 0.0,
            cube: [Mat4::ZERO; 6],
            shadow: ShadowFrustum::of_rsm(light_view_proj(light, near), rsm_half_fov(light).tan()),
        }],
        LightKind::Point => {
            let cube: [Mat4; 6] = std::array::from_fn(|f| {
                let axis = cube_face_axis(f);
                let view = Mat4::look_to_rh(light.position, axis, up_for(axis));
                projection(std::f32::consts::FRAC_PI_2, 1.0, near) * view
            });
            (0..6)
                .map(|f| LightView {
                    light: index,
                    kind: LightKind::Point,
                    face: Some(f),
                    view_proj: cube[f],
                    position: light.position,
                    direction: cube_face_axis(f),
                    half_extent: 1.0,
                    depth_range: 0.0,
                    cube,
                    shadow: ShadowFrustum::of_rsm(cube[f], 1.0),
                })
                .collect()
        }
        LightKind::Directional => {
            vec![directional_view(index, light, bounds, fit, rsm_resolution)]
        }
    }
}

/// The part of the scene a directional light's RSM covers when the scene's
/// bounds hold much more than the view needs (`renderer::directional_fit`):
/// the square covers `footprint`'s projection, its depth range also
/// `casters` (what may shadow the footprint).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalFit {
    pub footprint: (Vec3, Vec3),
    pub casters: (Vec3, Vec3),
}

/// What a directional light's RSM must cover for a view, when that is much
/// less than the scene (`None`: the whole scene, the usual case): a scene
/// whose bounds are stretched by a few far objects (a distant block, a
/// ground plane) would otherwise spread its RSM over them and leave the
/// part in view a few texels (issue 29). The footprint is what the camera
/// sees (`instances`' world boxes that meet the view frustum of
/// `camera_view_proj`) and what lies within one of its own extents around
/// it (which can still bounce light into view); it is used only when it is
/// under an eighth of the scene's extent. The casters are every instance
/// over the footprint as the light sees it.
pub fn fit_directional(
    direction: Vec3,
    instances: &[(Vec3, Vec3)],
    camera_view_proj: Mat4,
    scene: (Vec3, Vec3),
) -> Option<DirectionalFit> {
    let union = |boxes: &mut dyn Iterator<Item = (Vec3, Vec3)>| {
        boxes.reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
    };
    let visible = union(
        &mut instances
            .iter()
            .copied()
            .filter(|b| in_view(camera_view_proj, *b)),
    )?;
    let reach = visible.1 - visible.0;
    let near = (visible.0 - reach, visible.1 + reach);
    let overlaps =
        |(a, b): (Vec3, Vec3), (c, d): (Vec3, Vec3)| a.cmple(d).all() && c.cmple(b).all();
    let footprint = union(&mut instances.iter().copied().filter(|b| overlaps(*b, near)))?;
    let extent = |(a, b): (Vec3, Vec3)| (b - a).length();
    if extent(footprint) * 8.0 >= extent(scene) || extent(footprint).is_nan() {
        return None;
    }
    let rot = directional_frame(direction);
    let (fa, fb) = transformed_box(&rot, footprint);
    let over = |b: &(Vec3, Vec3)| {
        let (a, c) = transformed_box(&rot, *b);
        a.x <= fb.x && fa.x <= c.x && a.y <= fb.y && fa.y <= c.y
    };
    let casters = union(&mut instances.iter().copied().filter(over)).unwrap_or(footprint);
    Some(DirectionalFit { footprint, casters })
}

/// Whether the box meets the view frustum of `view_proj` (reversed-Z, no far
/// plane): not all its corners behind the eye or beyond one side plane.
fn in_view(view_proj: Mat4, (lo, hi): (Vec3, Vec3)) -> bool {
    let corners: Vec<glam::Vec4> = (0..8)
        .map(|i| {
            let c = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            view_proj * c.extend(1.0)
        })
        .collect();
    let all = |f: &dyn Fn(&glam::Vec4) -> bool| corners.iter().all(f);
    !(all(&|c| c.w <= 0.0)
        || all(&|c| c.x > c.w)
        || all(&|c| c.x < -c.w)
        || all(&|c| c.y > c.w)
        || all(&|c| c.y < -c.w))
}

/// The box `(lo, hi)` transformed by `m` (affine): the bounds of its eight corners.
pub fn transformed_box(m: &Mat4, (lo, hi): (Vec3, Vec3)) -> (Vec3, Vec3) {
    let (mut a, mut b) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let v = m.transform_point3(c);
        a = a.min(v);
        b = b.max(v);
    }
    (a, b)
}

/// The rotation into a directional light's frame (through the origin).
pub fn directional_frame(direction: Vec3) -> Mat4 {
    let d = direction.normalize();
    let up = if d.dot(Vec3::Y).abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    Mat4::look_to_rh(Vec3::ZERO, d, up)
}

/// The orthographic RSM of a directional light: a square perpendicular to
/// the light around the bounds' projection, its centre snapped to whole
/// texels of a grid fixed to the scene, so that the texel grid stays put on
/// the scene while the camera moves (docs/algorithm.md section 2.4).
fn directional_view(
    index: usize,
    light: &Light,
    (lo, hi): (Vec3, Vec3),
    fit: Option<&DirectionalFit>,
    r: u32,
) -> LightView {
    let d = light.direction.normalize();
    let up = if d.dot(Vec3::Y).abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    // The light's frame through the origin: rows of the rotation.
    let rot = Mat4::look_to_rh(Vec3::ZERO, d, up);
    // The square around the footprint; the depth range over the footprint
    // and what may cast onto it.
    let (footprint, casters) = match fit {
        Some(f) => (f.footprint, f.casters),
        None => ((lo, hi), (lo, hi)),
    };
    let (a, b) = transformed_box(&rot, footprint);
    let (za, zb) = transformed_box(&rot, casters);
    let (a, b) = (a.with_z(a.z.min(za.z)), b.with_z(b.z.max(zb.z)));
    // Half a texel of margin on each side so geometry on the bounds is inside.
    let raw_half = 0.5 * (b.x - a.x).max(b.y - a.y).max(f32::MIN_POSITIVE);
    // A fitted square changes only when the instances in its footprint do.
    let half = raw_half * (1.0 + 2.0 / r as f32);
    let texel = 2.0 * half / r as f32;
    // Snapped to whole texels from the footprint's corner: a grid fixed to
    // the scene, so it stays put as the camera (and the render origin)
    // moves, and moves with the scene when the whole scene is moved.
    let anchor = rot.transform_point3(footprint.0);
    let snap = |v: f32, at: f32| at + ((v - at) / texel).round() * texel;
    let (cx, cy) = (
        snap(0.5 * (a.x + b.x), anchor.x),
        snap(0.5 * (a.y + b.y), anchor.y),
    );
    // View space looks down -z: the nearest point to the light has the largest z.
    let margin = 0.01 * (b.z - a.z).max(half);
    let (z_near, z_far) = (b.z + margin, a.z - margin);
    let range = z_near - z_far;
    // Eye on the near plane, in world space.
    let inv = rot.inverse();
    let eye = inv.transform_point3(Vec3::new(cx, cy, z_near));
    let view = Mat4::look_to_rh(eye, d, up);
    // Reversed-Z: depth 1 at the near plane, 0 at the far one; y flipped.
    let ortho = Mat4::orthographic_rh(-half, half, -half, half, range, 0.0);
    let view_proj = Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0)) * ortho * view;
    LightView {
        light: index,
        kind: LightKind::Directional,
        face: None,
        view_proj,
        position: eye,
        direction: d,
        half_extent: half,
        depth_range: range,
        cube: [Mat4::ZERO; 6],
        shadow: ShadowFrustum::of_rsm(view_proj, half),
    }
}
