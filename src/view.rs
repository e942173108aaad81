//! Camera and light projections, shared by the GPU frame (`frame::uniforms`)
//! and the CPU path tracer, so both see the scene from the same places.

use crate::scene::{Camera, Light, LightKind, SpotLight};
use glam::{Mat4, Vec3};

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

/// World -> RSM clip: a square frustum around the spot's outer cone. The near
/// plane scales with the scene's size (`scene_extent`, the diagonal of its bounds).
pub fn light_view_proj(light: &SpotLight, scene_extent: f32) -> Mat4 {
    let up = if light.direction.dot(Vec3::Y).abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let view = Mat4::look_at_rh(light.position, light.position + light.direction, up);
    let near = (scene_extent * 1e-4).max(1e-6);
    projection(2.0 * rsm_half_fov(light), 1.0, near) * view
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
/// light. `bounds` (the scene's) fit the directional light's box and place
/// the perspective near plane; `rsm_resolution` snaps the box to texels.
pub fn light_views(
    index: usize,
    light: &Light,
    bounds: (Vec3, Vec3),
    rsm_resolution: u32,
) -> Vec<LightView> {
    let extent = (bounds.1 - bounds.0).length().max(1e-6);
    let near = (extent * 1e-4).max(1e-6);
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
            view_proj: light_view_proj(light, extent),
            position: light.position,
            direction: light.direction,
            half_extent: rsm_half_fov(light).tan(),
            depth_range: 0.0,
            cube: [Mat4::ZERO; 6],
        }],
        LightKind::Point => {
            let cube: [Mat4; 6] = std::array::from_fn(|f| {
                let axis = cube_face_axis(f);
                let view = Mat4::look_at_rh(light.position, light.position + axis, up_for(axis));
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
                })
                .collect()
        }
        LightKind::Directional => vec![directional_view(index, light, bounds, rsm_resolution)],
    }
}

/// The orthographic RSM of a directional light: a square perpendicular to
/// the light around the bounds' projection, its centre snapped to whole
/// texels in a frame fixed to the light's direction, so that the texel grid
/// stays put on the scene while the camera moves (docs/algorithm.md section 2.4).
fn directional_view(index: usize, light: &Light, (lo, hi): (Vec3, Vec3), r: u32) -> LightView {
    let d = light.direction.normalize();
    let up = if d.dot(Vec3::Y).abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    // The light's frame through the origin: rows of the rotation.
    let rot = Mat4::look_at_rh(Vec3::ZERO, d, up);
    let (mut a, mut b) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let v = rot.transform_point3(c);
        a = a.min(v);
        b = b.max(v);
    }
    // Half a texel of margin on each side so geometry on the bounds is inside.
    let raw_half = 0.5 * (b.x - a.x).max(b.y - a.y).max(1e-6);
    let half = raw_half * (1.0 + 2.0 / r as f32);
    let texel = 2.0 * half / r as f32;
    let snap = |v: f32| (v / texel).round() * texel;
    let (cx, cy) = (snap(0.5 * (a.x + b.x)), snap(0.5 * (a.y + b.y)));
    // View space looks down -z: the nearest point to the light has the largest z.
    let margin = 0.01 * (b.z - a.z).max(half);
    let (z_near, z_far) = (b.z + margin, a.z - margin);
    let range = z_near - z_far;
    // Eye on the near plane, in world space.
    let inv = rot.inverse();
    let eye = inv.transform_point3(Vec3::new(cx, cy, z_near));
    let view = Mat4::look_at_rh(eye, eye + d, up);
    // Reversed-Z: depth 1 at the near plane, 0 at the far one; y flipped.
    let ortho = Mat4::orthographic_rh(-half, half, -half, half, range, 0.0);
    LightView {
        light: index,
        kind: LightKind::Directional,
        face: None,
        view_proj: Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0)) * ortho * view,
        position: eye,
        direction: d,
        half_extent: half,
        depth_range: range,
        cube: [Mat4::ZERO; 6],
    }
}
