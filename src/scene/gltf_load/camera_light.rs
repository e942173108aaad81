//! Cameras and lights from glTF nodes, checked, and the defaults a scene
//! without them gets.

use super::*;

/// A perspective camera, refused when it cannot give an image: a singular
/// node transform (scale 0), a yfov outside what `check_yfov` allows, a
/// znear that is not a positive normal float. `check_znear` relates znear to the scene once bounds are known.
pub(super) fn read_camera(
    index: usize,
    node: usize,
    p: &gltf::camera::Perspective,
    world: Mat4,
) -> Result<Camera> {
    let (yfov, znear) = (p.yfov(), p.znear());
    if let Err(why) = crate::scene::check_yfov(yfov) {
        bail!(
            "camera {index}: yfov {} radians: {why}",
            crate::scene::text::number(yfov)
        );
    }
    if !(znear.is_normal() && znear > 0.0) {
        bail!("camera {index}: znear {znear} must be a positive, finite, normal number");
    }
    let Some(world_from_camera) = crate::scene::rigid(world) else {
        bail!(
            "camera {index}: the transform of its node {node} is singular (a scale of 0?), so it has no view direction"
        );
    };
    Ok(Camera {
        world_from_camera,
        yfov,
        znear,
    })
}

/// The linear part maps no direction to (nearly) zero (and all is finite).
pub(super) fn nonsingular(m: Mat4) -> bool {
    crate::scene::rigid(m).is_some()
}

/// Reversed-Z with an infinite far plane stores znear / distance: it must not
/// underflow for the farthest point of the scene.
pub(super) fn check_znear(index: usize, node: usize, c: &Camera, lo: Vec3, hi: Vec3) -> Result<()> {
    let eye = c.position();
    let far = (lo - eye).abs().max((hi - eye).abs()).length();
    if far.is_finite() && (c.znear as f64) < far as f64 * 1e-30 {
        bail!(
            "camera {index} (node {node}): znear {} is too small for a scene reaching {far:.3e} m from it: depths would underflow to zero (use znear >= {:.1e})",
            c.znear,
            far as f64 * 1e-30
        );
    }
    Ok(())
}

pub(super) fn read_light(l: &gltf::khr_lights_punctual::Light, world: Mat4) -> Result<SpotLight> {
    use crate::scene::LightKind;
    use gltf::khr_lights_punctual::Kind;
    let (kind, inner, outer) = match l.kind() {
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => (LightKind::Spot, inner_cone_angle, outer_cone_angle),
        // Cones mean nothing for these; the values are never read.
        Kind::Point => (LightKind::Point, 0.0, std::f32::consts::FRAC_PI_2),
        Kind::Directional => (LightKind::Directional, 0.0, std::f32::consts::FRAC_PI_2),
    };
    let half_pi = std::f32::consts::FRAC_PI_2;
    if kind == LightKind::Spot
        && !((0.0..half_pi).contains(&inner) && outer > inner && outer <= half_pi)
    {
        bail!(
            "light {} (spot): cone angles must satisfy 0 <= inner < outer <= pi/2, i.e. the outer cone above the inner one and at most 90 degrees (got inner {inner}, outer {outer} radians)",
            l.index()
        );
    }
    if !(l.intensity().is_finite() && l.intensity() >= 0.0) {
        bail!(
            "light {}: intensity {} must be finite and non-negative",
            l.index(),
            l.intensity()
        );
    }
    let color = Vec3::from(l.color());
    if !(color.is_finite() && color.min_element() >= 0.0 && (color * l.intensity()).is_finite()) {
        bail!(
            "light {}: color {:?} must be finite and non-negative",
            l.index(),
            l.color()
        );
    }
    if let Some(r) = l.range() {
        if !(r.is_finite() && r > 0.0) {
            bail!("light {}: range {r} must be finite and positive", l.index());
        }
    }
    let direction = world.transform_vector3(-Vec3::Z);
    if !direction.is_finite() || direction.length_squared() == 0.0 || !nonsingular(world) {
        bail!(
            "light {}: its node transform is degenerate (a scale of 0?)",
            l.index()
        );
    }
    Ok(SpotLight {
        kind,
        position: world.transform_point3(Vec3::ZERO),
        direction: direction.normalize(),
        color,
        intensity: l.intensity(),
        inner_cone: inner,
        outer_cone: outer,
        range: l.range(),
    })
}

pub(super) fn default_light() -> SpotLight {
    fitted_light(Vec3::splat(-1.0), Vec3::splat(1.0))
}

pub(super) fn default_camera() -> Camera {
    fitted_camera(Vec3::splat(-1.0), Vec3::splat(1.0))
}

/// A spot light just below the top of the bounds, pointing down, bright enough
/// that a white floor at the bottom reflects radiance of about 1 (docs/algorithm.md section 2).
/// Finite for any finite bounds: sizes are taken in f64 and the intensity is
/// clamped to the largest f32 (only reached far beyond `Limits::coordinate`).
pub fn fitted_light(lo: Vec3, hi: Vec3) -> SpotLight {
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    // Scale-free: the loader refuses scenes below `Limits::min_extent`.
    let size = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let center = (lo + hi) * 0.5;
    let position = glam::DVec3::new(center.x, hi.y - 0.05 * size, center.z);
    let drop = (position.y - lo.y).max(0.1 * size);
    SpotLight {
        kind: crate::scene::LightKind::Spot,
        position: position.as_vec3(),
        direction: -Vec3::Y,
        color: Vec3::ONE,
        intensity: (std::f64::consts::PI * drop * drop)
            .clamp(f32::MIN_POSITIVE as f64, f32::MAX as f64) as f32,
        inner_cone: 45f32.to_radians(),
        outer_cone: 60f32.to_radians(),
        range: None,
    }
}

/// A camera on +Z of the bounds, framing them with a 45 degree vertical fov.
/// Computed in f64 so that it stays finite for any finite bounds.
pub fn fitted_camera(lo: Vec3, hi: Vec3) -> Camera {
    // Bounds beyond f32::MAX / 8 (refused by the loader long before, see
    // `Limits::coordinate`) are clamped so the eye stays a finite f32.
    let m = f32::MAX as f64 / 8.0;
    let clamp = |v: Vec3| {
        v.as_dvec3()
            .clamp(glam::DVec3::splat(-m), glam::DVec3::splat(m))
    };
    let (lo, hi) = (clamp(lo), clamp(hi));
    let center = (lo + hi) * 0.5;
    // At least a millionth of the distance from the origin, so that the eye
    // is a different f32 from the centre even for a point far out.
    let radius = ((hi - lo).length() * 0.5)
        .max(f64::MIN_POSITIVE)
        .max(center.abs().max_element() * 1e-6);
    let yfov = 45f64.to_radians();
    let distance = radius / (yfov * 0.5).sin();
    let eye = center + glam::DVec3::Z * distance;
    let view = glam::DMat4::look_at_rh(eye, center, glam::DVec3::Y);
    let znear = (distance - radius).max(distance * 1e-3);
    Camera {
        world_from_camera: view.inverse().as_mat4(),
        yfov: yfov as f32,
        znear: (znear as f32).min(f32::MAX),
    }
}
