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
use glam::{DVec3, Mat4, Vec3, Vec4};

fn vec3(a: [f32; 3], what: &str) -> Result<Vec3> {
    let v = Vec3::from(a);
    if !v.is_finite() {
        bail!("{what} {a:?} is not finite");
    }
    Ok(v)
}

/// A position in world metres, within the coordinate budget
/// (`Limits::coordinate`), relative to the scene's origin (`Scene::origin`,
/// subtracted in f64).
pub(super) fn point(a: [f64; 3], what: &str, origin: DVec3) -> Result<Vec3> {
    let v = DVec3::from(a);
    if !v.is_finite() {
        bail!("{what} {a:?} is not finite");
    }
    let limit = crate::scene::limits::Limits::DEFAULT.coordinate;
    if v.abs().max_element() > limit as f64 {
        bail!("{what} {a:?} reaches beyond {limit:.0e} m, the largest coordinate isr supports");
    }
    Ok((v - origin).as_vec3())
}

/// One keyframe resolved: time, position, where it points.
pub(super) struct Pose {
    t: f32,
    position: Vec3,
    direction: Vec3,
}

/// The light `spec` gives (positions in world metres) in the scene's frame:
/// `pivot` its centre, `origin` where its coordinates start.
pub(super) fn light(
    spec: &LightSpec,
    pivot: Vec3,
    origin: DVec3,
) -> Result<(Light, Option<Vec<Pose>>)> {
    let kind = match spec.kind.trim().to_ascii_lowercase().as_str() {
        "spot" => LightKind::Spot,
        "point" => LightKind::Point,
        "directional" | "sun" => LightKind::Directional,
        _ => bail!(
            "type '{}': a light is spot, point or directional",
            crate::scene::text::quote(&spec.kind)
        ),
    };
    let first = spec.path.as_ref().and_then(|p| p.first());
    let position = spec.position.or(first.and_then(|k| k.position));
    let target = spec.target.or(first.and_then(|k| k.target));
    let direction = spec.direction.or(first.and_then(|k| k.direction));
    let point = |a: [f64; 3], what: &str| point(a, what, origin);
    let (position, direction) = match kind {
        LightKind::Directional => {
            if spec.target.is_some() && direction.is_none() {
                let p = point(position.ok_or_else(|| anyhow!("a directional light with a target needs a position (the rays go from it to the target), or give its direction"))?, "position")?;
                let t = point(target.unwrap_or_default(), "target")?;
                (p, t - p)
            } else {
                let d = direction.ok_or_else(|| {
                    anyhow!("a directional light needs a direction (its rays, e.g. [0.3, -1, 0.2])")
                })?;
                (
                    position.map_or(Ok(pivot), |p| point(p, "position"))?,
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
    let Some(direction) = crate::scene::direction(direction) else {
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
            let aim = match target {
                Some(t) => point(t, "target")?,
                None => pivot,
            };
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
        target.map(|t| point(t, "target")).transpose()?,
        kind == LightKind::Directional,
        pivot,
        origin,
    )?;
    Ok((light, motion))
}

/// The camera `spec` gives, in the scene's frame, as [`light`].
pub(super) fn camera(
    spec: &CameraSpec,
    pivot: Vec3,
    diagonal: f32,
    origin: DVec3,
) -> Result<(Camera, Option<Vec<Pose>>)> {
    let point = |a: [f64; 3], what: &str| point(a, what, origin);
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
    let Some(direction) = crate::scene::direction(target - position) else {
        bail!("the camera's target is its position: it looks nowhere");
    };
    let fov = spec.fov.unwrap_or(45.0);
    crate::scene::check_yfov(fov.to_radians())
        .map_err(|why| anyhow!("fov {} (degrees): {why}", crate::scene::text::number(fov)))?;
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
        origin,
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
    origin: DVec3,
) -> Result<Option<Vec<Pose>>> {
    let point = |a: [f64; 3], what: &str| point(a, what, origin);
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
                let Some(d) = crate::scene::direction(direction) else {
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
                Some(c) => point(c, "orbit center")?,
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
                        Some(a) => {
                            crate::scene::direction(a - position).unwrap_or(rot * rest.direction)
                        }
                        None => rot * rest.direction,
                    };
                    Pose {
                        t: s * o.period,
                        position,
                        direction,
                    }
                })
                .collect::<Vec<Pose>>();
            // The circle through the rest position, whatever the centre:
            // held to the coordinate budget as every key of a path is.
            let limit = crate::scene::limits::Limits::DEFAULT.coordinate;
            let far = out
                .iter()
                .map(|k| (origin + k.position.as_dvec3()).abs().max_element() as f32)
                .fold(0f32, |m, r| {
                    if m.is_nan() || r.is_nan() {
                        f32::NAN
                    } else {
                        m.max(r)
                    }
                });
            if far.is_nan() || far > limit {
                bail!(
                    "the orbit about {} reaches {far:.3e} m from the origin; isr supports coordinates up to {limit:.0e} m",
                    origin + center.as_dvec3()
                );
            }
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
