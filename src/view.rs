//! Camera and light projections, shared by the GPU frame (`frame::uniforms`)
//! and the CPU path tracer, so both see the scene from the same places.

use crate::scene::{Camera, SpotLight};
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
