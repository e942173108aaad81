//! The lights and camera of a description (or of `--light` and
//! `--camera`), and their motion: paths and orbits as keyframes of the glTF
//! animation machinery. Every position, target and orbit centre is held to
//! the coordinate budget, every direction normalised at any finite length,
//! and a field of view to what a camera can render (`check_yfov`).

use super::{CameraSpec, Key, LightSpec, Orbit};
use crate::scene::animation::{
    rotation_looking_along, Animation, Channel, Interpolation, Local, Parent, Property, Trs,
};
use crate::scene::{Camera, Light, LightKind};
use anyhow::{anyhow, bail, Result};
use glam::{Mat4, Vec3, Vec4};

fn vec3(a: [f32; 3], what: &str) -> Result<Vec3> {
    let v = Vec3::from(a);
    if !v.is_finite() {
        bail!("{what} {a:?} is not finite");
    }
    Ok(v)
}

/// A position, within the coordinate budget (`Limits::coordinate`).
pub(super) fn point(a: [f32; 3], what: &str) -> Result<Vec3> {
    let v = vec3(a, what)?;
    let limit = crate::scene::limits::Limits::DEFAULT.coordinate;
    if v.abs().max_element() > limit {
        bail!("{what} {a:?} reaches beyond {limit:.0e} m, the largest coordinate isr supports");
    }
    Ok(v)
}

/// One keyframe resolved: time, position, where it points.
pub(super) struct Pose {
    t: f32,
    position: Vec3,
    direction: Vec3,
}

pub(super) fn light(spec: &LightSpec, pivot: Vec3) -> Result<(Light, Option<Vec<Pose>>)> {
    let kind = match spec.kind.trim().to_ascii_lowercase().as_str() {
        "spot" => LightKind::Spot,
        "point" => LightKind::Point,
        "directional" | "sun" => LightKind::Directional,
        other => bail!("type {other:?}: a light is spot, point or directional"),
    };
    let first = spec.path.as_ref().and_then(|p| p.first());
    let position = spec.position.or(first.and_then(|k| k.position));
    let target = spec.target.or(first.and_then(|k| k.target));
    let direction = spec.direction.or(first.and_then(|k| k.direction));
    let (position, direction) = match kind {
        LightKind::Directional => {
            if spec.target.is_some() && direction.is_none() {
                let p = vec3(position.ok_or_else(|| anyhow!("a directional light with a target needs a position (the rays go from it to the target), or give its direction"))?, "position")?;
                let t = vec3(target.unwrap_or_default(), "target")?;
                (p, t - p)
            } else {
                let d = direction.ok_or_else(|| {
                    anyhow!("a directional light needs a direction (its rays, e.g. [0.3, -1, 0.2])")
                })?;
                (
                    position.map_or(Ok(pivot), |p| vec3(p, "position"))?,
                    vec3(d, "direction")?,
                )
            }
        }
        LightKind::Spot | LightKind::Point => {
            let p = point(
                position.ok_or_else(|| anyhow!("a {} light needs a position", spec.kind))?,
                "position",
            )?;
            let d = match (target, direction) {
                (Some(t), _) => point(t, "target")? - p,
                (None, Some(d)) => vec3(d, "direction")?,
                (None, None) if kind == LightKind::Point => -Vec3::Y,
                (None, None) => bail!("a spot light needs a target (or a direction) to point at"),
            };
            (p, d)
        }
    };
    let Some(direction) = direction.try_normalize() else {
        bail!("the light points nowhere: its target is its position (or its direction is zero)");
    };
    let color = vec3(spec.color.unwrap_or([1.0; 3]), "color")?;
    if color.min_element() < 0.0 {
        bail!("color {color}: must be non-negative");
    }
    let outer = spec.cone.unwrap_or(45.0);
    let inner = spec.inner_cone.unwrap_or(outer * 0.75);
    if kind == LightKind::Spot && !(inner >= 0.0 && inner < outer && outer <= 90.0) {
        bail!(
            "cone {outer}, inner_cone {inner} (degrees): they must satisfy 0 <= inner < outer <= 90"
        );
    }
    // Default intensity: a white surface facing the light at the target (or
    // at the scene's centre) reflects radiance 1: E = pi.
    let reach = match kind {
        LightKind::Directional => 1.0,
        _ => {
            let aim = target.map(Vec3::from).unwrap_or(pivot);
            (aim - position).length().max(1e-6)
        }
    };
    let intensity = spec
        .intensity
        .unwrap_or(std::f32::consts::PI * reach * reach);
    if !(intensity.is_finite() && intensity >= 0.0 && (color * intensity).is_finite()) {
        bail!("intensity {intensity}: must be finite and non-negative");
    }
    if let Some(r) = spec.range {
        if !(r.is_finite() && r > 0.0) {
            bail!("range {r}: must be finite and positive");
        }
    }
    let light = Light {
        kind,
        position,
        direction,
        color,
        intensity,
        inner_cone: if kind == LightKind::Spot {
            inner.to_radians()
        } else {
            0.0
        },
        outer_cone: if kind == LightKind::Spot {
            outer.to_radians()
        } else {
            std::f32::consts::FRAC_PI_2
        },
        range: spec.range,
    };
    let motion = motion(
        spec.path.as_deref(),
        spec.orbit.as_ref(),
        Pose {
            t: 0.0,
            position,
            direction,
        },
        target.map(Vec3::from),
        kind == LightKind::Directional,
        pivot,
    )?;
    Ok((light, motion))
}

pub(super) fn camera(
    spec: &CameraSpec,
    pivot: Vec3,
    diagonal: f32,
) -> Result<(Camera, Option<Vec<Pose>>)> {
    let first = spec.path.as_ref().and_then(|p| p.first());
    let position = spec
        .position
        .or(first.and_then(|k| k.position))
        .ok_or_else(|| anyhow!("the camera needs a position"))?;
    let position = point(position, "position")?;
    let target = spec.target.or(first.and_then(|k| k.target));
    let target = match target {
        Some(t) => point(t, "target")?,
        None => pivot,
    };
    let Some(direction) = (target - position).try_normalize() else {
        bail!("the camera's target is its position: it looks nowhere");
    };
    let fov = spec.fov.unwrap_or(45.0);
    if !(fov > 0.0 && fov < 180.0) {
        bail!("fov {fov}: the vertical field of view is more than 0 and less than 180 degrees");
    }
    let far = (diagonal + (position - pivot).length()).max(f32::MIN_POSITIVE);
    let znear = spec
        .znear
        .unwrap_or((diagonal * 1e-3).max(f32::MIN_POSITIVE));
    if !(znear.is_normal() && znear > 0.0) {
        bail!("znear {znear}: must be a positive number of metres");
    }
    if (znear as f64) < far as f64 * 1e-30 {
        bail!("znear {znear} is too small for a scene reaching {far:.3e} m from the camera: depths would underflow (use znear >= {:.1e})", far as f64 * 1e-30);
    }
    let camera = Camera {
        world_from_camera: Mat4::from_rotation_translation(
            rotation_looking_along(direction),
            position,
        ),
        yfov: fov.to_radians(),
        znear,
    };
    let motion = motion(
        spec.path.as_deref(),
        spec.orbit.as_ref(),
        Pose {
            t: 0.0,
            position,
            direction,
        },
        Some(target),
        false,
        pivot,
    )?;
    Ok((camera, motion))
}

/// The keyframes of a path or an orbit (none without either).
fn motion(
    path: Option<&[Key]>,
    orbit: Option<&Orbit>,
    rest: Pose,
    target: Option<Vec3>,
    directional: bool,
    pivot: Vec3,
) -> Result<Option<Vec<Pose>>> {
    match (path, orbit) {
        (None, None) => Ok(None),
        (Some(_), Some(_)) => bail!("give a path or an orbit, not both"),
        (Some(keys), None) => {
            if keys.is_empty() {
                bail!("the path has no keyframes");
            }
            let mut out = Vec::with_capacity(keys.len());
            let (mut position, mut target, mut direction) = (rest.position, target, rest.direction);
            for (i, k) in keys.iter().enumerate() {
                let what = |f: &str| format!("path key {i}: {f}");
                if !k.t.is_finite() {
                    bail!("{}", what(&format!("t {} is not finite", k.t)));
                }
                if let Some(p) = k.position {
                    position = point(p, &what("position"))?;
                }
                if let Some(t) = k.target {
                    target = Some(point(t, &what("target"))?);
                }
                if let Some(d) = k.direction {
                    direction = vec3(d, &what("direction"))?;
                } else if let Some(t) = target {
                    if !directional {
                        direction = t - position;
                    }
                }
                let Some(d) = direction.try_normalize() else {
                    bail!("{}", what("the target is the position: it points nowhere"));
                };
                out.push(Pose {
                    t: k.t,
                    position,
                    direction: d,
                });
            }
            Ok(Some(out))
        }
        (None, Some(o)) => {
            if !(o.period.is_finite() && o.period > 0.0) {
                bail!("orbit period {}: a positive number of seconds", o.period);
            }
            let turns = o.turns.unwrap_or(1.0);
            if !(turns.is_finite() && turns > 0.0 && turns <= 1000.0) {
                bail!("orbit turns {turns}: a positive number, at most 1000");
            }
            let center = match o.center {
                Some(c) => vec3(c, "orbit center")?,
                None => pivot,
            };
            let aim = if directional {
                None
            } else {
                Some(target.unwrap_or_else(|| {
                    crate::scene::motion::aim_point(rest.position, rest.direction, center)
                }))
            };
            // 64 keys a turn: linear between them, the path is within 0.12%
            // of the radius of the circle.
            let n = (64.0 * turns).ceil() as usize;
            let out = (0..=n)
                .map(|k| {
                    let s = k as f32 / n as f32 * turns;
                    let rot = glam::Quat::from_rotation_y(std::f32::consts::TAU * s);
                    let position = center + rot * (rest.position - center);
                    let direction = match aim {
                        Some(a) => (a - position).normalize_or(rot * rest.direction),
                        None => rot * rest.direction,
                    };
                    Pose {
                        t: s * o.period,
                        position,
                        direction,
                    }
                })
                .collect();
            Ok(Some(out))
        }
    }
}

/// A node of `a` moving along `keys` (translation and rotation, linear):
/// its index.
pub(super) fn add_path(a: &mut Animation, keys: &[Pose]) -> Result<usize> {
    let rest = Trs {
        translation: keys[0].position,
        rotation: rotation_looking_along(keys[0].direction),
        scale: Vec3::ONE,
    };
    let node = a
        .add_node(Parent::Fixed(Mat4::IDENTITY), Local::Animated(rest))
        .map_err(|e| anyhow!(e))?;
    let times: Vec<f32> = keys.iter().map(|k| k.t).collect();
    let translations = keys.iter().map(|k| k.position.extend(0.0)).collect();
    let rotations = keys
        .iter()
        .map(|k| Vec4::from(rotation_looking_along(k.direction)))
        .collect();
    for (property, values) in [
        (Property::Translation, translations),
        (Property::Rotation, rotations),
    ] {
        let c = Channel::new(node, property, Interpolation::Linear, times.clone(), values)
            .map_err(|e| anyhow!("the path: {e}"))?;
        a.add_channel(c.labelled(format!("the path's {}", property.name())))
            .map_err(|e| anyhow!(e))?;
    }
    Ok(node)
}
