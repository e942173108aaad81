//! Lights and the camera of a scene, and the origin the GPU renders
//! relative to.

use glam::{Mat4, Vec3};

/// What kind of `KHR_lights_punctual` light (docs/algorithm.md section 2.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightKind {
    /// A cone: intensity in candela (W/sr), the cones below apply.
    #[default]
    Spot,
    /// All around: intensity in candela (W/sr); the cones are ignored.
    Point,
    /// Parallel rays along `direction`: intensity in lux, read as the
    /// irradiance E (W/m^2) on a surface facing the light; position, cones
    /// and range are ignored.
    Directional,
}

impl LightKind {
    pub fn name(self) -> &'static str {
        match self {
            LightKind::Spot => "spot",
            LightKind::Point => "point",
            LightKind::Directional => "directional",
        }
    }
}

/// A `KHR_lights_punctual` light (docs/algorithm.md sections 2.3 and 2.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    pub position: Vec3,
    /// Unit vector the cone (or the directional light's rays) points along (the node's -Z).
    pub direction: Vec3,
    /// Linear RGB color.
    pub color: Vec3,
    /// Spot and point: luminous intensity in candela, treated as W/sr.
    /// Directional: illuminance in lux, treated as irradiance E in W/m^2.
    pub intensity: f32,
    /// Radians; attenuation is smooth between inner and outer (spot lights only).
    pub inner_cone: f32,
    pub outer_cone: f32,
    /// Distance cut-off; `None` means none (the extension's default).
    pub range: Option<f32>,
}

/// The name most of the code knew the light by, when spot lights were all there was.
pub type SpotLight = Light;

impl Light {
    /// The extension's angular attenuation, squared smoothstep between the
    /// cones; 1 for point and directional lights.
    pub fn angular_attenuation(&self, cos_angle: f64) -> f64 {
        if self.kind != LightKind::Spot {
            return 1.0;
        }
        let (scale, offset) = self.cone_scale_offset();
        let t = (cos_angle * scale as f64 + offset as f64).clamp(0.0, 1.0);
        t * t
    }

    /// `lightAngleScale` and `lightAngleOffset` as KHR_lights_punctual defines them.
    pub fn cone_scale_offset(&self) -> (f32, f32) {
        let cos_outer = self.outer_cone.cos();
        let cos_inner = self.inner_cone.cos();
        let scale = 1.0 / (cos_inner - cos_outer).max(0.001);
        (scale, -cos_outer * scale)
    }

    /// Radiant intensity (W/sr) toward world point `p`, per color channel,
    /// including the range window when a range is set. Spot and point lights.
    pub fn intensity_toward(&self, p: glam::DVec3) -> glam::DVec3 {
        let to = p - self.position.as_dvec3();
        let d = to.length();
        let cos = to.dot(self.direction.as_dvec3()) / d;
        let mut i = self.color.as_dvec3() * self.intensity as f64 * self.angular_attenuation(cos);
        if let Some(range) = self.range {
            let r = d / range as f64;
            i *= (1.0 - r.powi(4)).clamp(0.0, 1.0);
        }
        i
    }

    /// Irradiance (W/m^2, per channel) on a surface at `p` facing the light,
    /// unshadowed: `I(w) / d^2` for spot and point lights, `E` for directional
    /// ones (docs/algorithm.md section 2.4).
    pub fn irradiance_facing(&self, p: glam::DVec3) -> glam::DVec3 {
        match self.kind {
            LightKind::Directional => self.color.as_dvec3() * self.intensity as f64,
            _ => self.intensity_toward(p) / (p - self.position.as_dvec3()).length_squared(),
        }
    }

    /// Unit vector from `p` toward the light.
    pub fn direction_from(&self, p: glam::DVec3) -> glam::DVec3 {
        match self.kind {
            LightKind::Directional => -self.direction.as_dvec3().normalize(),
            _ => (self.position.as_dvec3() - p).normalize(),
        }
    }
}

/// A perspective camera looking down its local -Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Rotation and translation only ([`rigid`]): a camera's node may be
    /// scaled (a scene scaled as a whole scales its camera's node too), but
    /// its field of view and znear are its own, so the view is the node's
    /// placement without the scale.
    pub world_from_camera: Mat4,
    /// Vertical field of view, radians.
    pub yfov: f32,
    pub znear: f32,
}

impl Camera {
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, yfov: f32, znear: f32) -> Self {
        Self {
            world_from_camera: Mat4::look_at_rh(eye, target, up).inverse(),
            yfov,
            znear,
        }
    }

    pub fn position(&self) -> Vec3 {
        self.world_from_camera.w_axis.truncate()
    }

    pub fn forward(&self) -> Vec3 {
        (-self.world_from_camera.z_axis.truncate()).normalize()
    }
}

/// Whether a camera with the vertical field of view `yfov` (radians) can
/// render: its projection's scale `1 / tan(yfov / 2)` within [1e-6, 1e6],
/// so `yfov` within about [2e-6, pi - 2e-6]. Narrower, neighbouring pixels'
/// rays differ by less than f32 tells apart from the camera's own
/// direction (measured on the built-in box: a view 1.7e-7 radians wide
/// renders, at 1.7e-8 a quarter of the image is black, at 1.7e-22 three
/// quarters); wider, the scale rounds to 0. The same bound for glTF
/// cameras, descriptions and `--camera`. The error says why.
pub fn check_yfov(yfov: f32) -> Result<(), String> {
    let f = 1.0 / (0.5 * yfov as f64).tan();
    if yfov > 0.0 && yfov < std::f32::consts::PI && (1e-6..=1e6).contains(&f) {
        return Ok(());
    }
    Err(format!(
        "the vertical field of view must be between {:.2e} and {:.6} degrees ({:.0e} to pi - {:.0e} radians: a view narrower than that is finer than 32-bit floats resolve)",
        MIN_YFOV.to_degrees(),
        (std::f64::consts::PI - MIN_YFOV as f64).to_degrees(),
        MIN_YFOV,
        MIN_YFOV
    ))
}

/// The narrowest field of view [`check_yfov`] allows, radians (the widest
/// is pi minus it).
pub const MIN_YFOV: f32 = 2e-6;

/// The rotation and translation of `m`, without its scale: `None` when `m`
/// is not finite or maps some direction to (nearly) zero (a scale of 0),
/// so that it has no orientation.
pub fn rigid(m: Mat4) -> Option<Mat4> {
    let l = glam::Mat3::from_mat4(m);
    let lengths = l.x_axis.length() * l.y_axis.length() * l.z_axis.length();
    let det = l.determinant();
    let regular =
        lengths.is_finite() && lengths > 0.0 && det.is_finite() && det.abs() > 1e-6 * lengths;
    if !(regular && m.w_axis.is_finite()) {
        return None;
    }
    let (_, rotation, translation) = m.to_scale_rotation_translation();
    rotation
        .is_finite()
        .then(|| Mat4::from_rotation_translation(rotation.normalize(), translation))
}

/// The origin the GPU renders relative to, for `camera`: its position
/// snapped to a grid whose cell is the power of two at or above 64 times
/// its znear ([`render_origin_cell`]). Positions on the GPU are then what
/// they would be with the camera near the world's origin, wherever the
/// scene is, and keep the precision they have there; the origin moves only
/// when the camera crosses a cell; and a scene moved by whole cells, or
/// scaled by a power of two (znear with it), renders from exactly the same
/// (or exactly scaled) numbers.
pub fn render_origin(camera: &Camera) -> glam::DVec3 {
    let cell = render_origin_cell(camera.znear);
    (camera.position().as_dvec3() / cell).round() * cell
}

/// See [`render_origin`]: the camera is then within 56 znear of the
/// origin, so geometry it sees (at least znear away) has relative
/// coordinates no more than about 57 times its distance, a loss of under
/// 6 bits of float precision at the nearest and less beyond.
pub fn render_origin_cell(znear: f32) -> f64 {
    let z = znear as f64 * 64.0;
    if !(z.is_finite() && z > 0.0) {
        return 1.0;
    }
    2f64.powi(z.log2().ceil() as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spot_attenuation_follows_khr_lights_punctual() {
        let l = SpotLight {
            kind: LightKind::Spot,
            position: Vec3::ZERO,
            direction: -Vec3::Y,
            color: Vec3::ONE,
            intensity: 1.0,
            inner_cone: 0.3,
            outer_cone: 0.6,
            range: None,
        };
        assert_eq!(l.angular_attenuation(1.0), 1.0);
        assert!((l.angular_attenuation(0.3f64.cos()) - 1.0).abs() < 1e-6);
        assert_eq!(l.angular_attenuation(0.7f64.cos()), 0.0);
        // Halfway in cosine between the cones: (1/2)^2.
        let mid = 0.5 * (0.3f64.cos() + 0.6f64.cos());
        assert!((l.angular_attenuation(mid) - 0.25).abs() < 1e-4);
    }
}
