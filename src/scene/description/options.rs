//! The command line's short form of a light and a camera (`--light`,
//! `--camera`), checked before a device is opened.

use super::lights::{camera, light};
use super::{CameraSpec, LightSpec};
use glam::Vec3;

/// `--light`: `KIND:KEY=VALUE:...`, KIND spot, point or directional; keys
/// `position` (`pos`), `target`, `direction` (`dir`), `intensity`,
/// `color`, `cone`, `inner` (degrees), `range`; vectors as `X,Y,Z`.
pub fn parse_light(s: &str) -> Result<LightSpec, String> {
    let mut parts = s.split(':');
    let kind = parts.next().unwrap_or_default().trim().to_string();
    if !matches!(
        kind.to_ascii_lowercase().as_str(),
        "spot" | "point" | "directional" | "sun"
    ) {
        return Err(format!(
            "'{kind}': a light starts with its type, spot, point or directional (e.g. spot:position=0,4,0:target=0,0,0:cone=40)"
        ));
    }
    let mut l = LightSpec {
        kind,
        ..Default::default()
    };
    for part in parts {
        let (key, value) = key_value(part)?;
        match key {
            "position" | "pos" => l.position = Some(place(key, value)?),
            "target" => l.target = Some(place(key, value)?),
            "direction" | "dir" => l.direction = Some(vector(key, value)?),
            "color" | "colour" => l.color = Some(vector(key, value)?),
            "intensity" => l.intensity = Some(number(key, value)?),
            "cone" => l.cone = Some(number(key, value)?),
            "inner" | "inner_cone" => l.inner_cone = Some(number(key, value)?),
            "range" => l.range = Some(number(key, value)?),
            _ => {
                return Err(format!(
                    "'{key}': a light takes position, target, direction, intensity, color, cone, inner and range"
                ))
            }
        }
    }
    // The checks that need no scene, now: before a device is opened.
    light(&l, Vec3::ZERO, glam::DVec3::ZERO).map_err(|e| format!("{e:#}"))?;
    Ok(l)
}

/// `--camera`: `KEY=VALUE:...`, keys `position` (`pos`), `target`, `fov`
/// (vertical, degrees), `znear` (metres).
pub fn parse_camera(s: &str) -> Result<CameraSpec, String> {
    let mut c = CameraSpec::default();
    for part in s.split(':') {
        let (key, value) = key_value(part)?;
        match key {
            "position" | "pos" => c.position = Some(place(key, value)?),
            "target" => c.target = Some(place(key, value)?),
            "fov" => c.fov = Some(number(key, value)?),
            "znear" => c.znear = Some(number(key, value)?),
            _ => {
                return Err(format!(
                    "'{key}': the camera takes position, target, fov and znear"
                ))
            }
        }
    }
    if c.position.is_none() {
        return Err("the camera needs a position (position=X,Y,Z)".into());
    }
    camera(&c, Vec3::ZERO, 1.0, glam::DVec3::ZERO).map_err(|e| format!("{e:#}"))?;
    Ok(c)
}

fn key_value(part: &str) -> Result<(&str, &str), String> {
    part.split_once('=')
        .map(|(k, v)| (k.trim(), v.trim()))
        .ok_or_else(|| format!("'{part}': expected KEY=VALUE"))
}

fn number(key: &str, value: &str) -> Result<f32, String> {
    value
        .parse::<f32>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| format!("{key}={value}: not a finite number"))
}

fn vector(key: &str, value: &str) -> Result<[f32; 3], String> {
    let v: Vec<f32> = value
        .split(',')
        .map(|x| number(key, x.trim()))
        .collect::<Result<_, _>>()?;
    v.try_into()
        .map_err(|_| format!("{key}={value}: a vector is X,Y,Z"))
}

/// A place in world metres, in f64 (`LightSpec::position`).
fn place(key: &str, value: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = value
        .split(',')
        .map(|x| {
            let x = x.trim();
            x.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{key}={x}: not a finite number"))
        })
        .collect::<Result<_, _>>()?;
    v.try_into()
        .map_err(|_| format!("{key}={value}: a vector is X,Y,Z"))
}
