//! A camera and a light for a bare scene (an OBJ, a glTF without them, no
//! description: `Scene::bare`), placed by looking at the scene
//! (docs/guide.md section 2, "A bare scene"):
//!
//! - Bounds: those of most of the surface area along each axis (its
//!   middle 80%, widened: `probe::robust_bounds`), so that a stray
//!   triangle far away moves nothing.
//! - Enclosure or object: rays from the bounds' centre in all directions
//!   (the path tracer's BVH). Most hit, and hit surfaces facing the centre:
//!   it is inside something one can stand in (a nave, an atrium, a room).
//!   Otherwise (rays escape, or the centre is inside a closed solid): an
//!   object seen from outside.
//! - Inside: the camera stands at a third of the floor-to-ceiling height,
//!   near one end of the longest horizontal axis, looking along it. The
//!   light: a sun through the roof when rays up from the middle of the
//!   floor escape, else a spot under the ceiling pointing down.
//! - Outside: the camera frames the bounds from the side showing the most
//!   surface; a spot above and beside it lights them.
//!
//! Intensities follow the rule of `--light` (docs/guide.md section 2): a
//! white surface facing the light at its target reflects radiance 1
//! (`pi d^2` cd, `pi` lux for a sun). Everything is relative to the
//! scene's size: the same scene scaled is placed the same way, scaled.

mod probe;

use crate::scene::{Camera, Light, LightKind, Scene};
use glam::DVec3;
use probe::Rays;

/// Rays per probe of the sphere around a point.
const PROBE_RAYS: usize = 256;
/// Rays over the sphere when looking for the sky (the quarter above 30
/// degrees is used: about 1,000, 3.6 degrees apart).
const SKY_RAYS: usize = 4096;
/// Surface samples for the robust bounds and the camera's side.
const SAMPLES: usize = 16_384;

/// What was placed, for the line the command line prints.
#[derive(Clone, Debug)]
pub struct Placed {
    /// Inside an enclosure (else an object from outside).
    pub inside: bool,
    /// The light is a sun through an opening above.
    pub sun: bool,
    /// One line: what was placed and the `--camera` / `--light` that keep it.
    pub line: String,
}

/// Places the camera and the light of `scene` that its loader made up
/// (`Scene::bare`); `None` when it has its own (or no geometry).
pub fn place_bare(scene: &mut Scene) -> Option<Placed> {
    if !(scene.bare.light || scene.bare.camera) {
        return None;
    }
    let tris = probe::triangles(scene);
    let samples = probe::surface_samples(&tris, SAMPLES);
    if samples.is_empty() {
        return None;
    }
    let (lo, hi) = probe::robust_bounds(&samples);
    let center = (lo + hi) * 0.5;
    let size = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let rays = Rays::new(&tris, center);
    let dirs = probe::sphere(PROBE_RAYS);
    let found: Vec<_> = dirs.iter().map(|&d| rays.cast(center, d)).collect();
    let hits = found.iter().flatten().count();
    let backs = found.iter().flatten().filter(|f| f.back).count();
    // Most rays hit (an opening above, as Sponza's, leaves a quarter of
    // them free), and most of what they hit faces the centre: a closed
    // solid (the bunny) is seen from inside by its back faces.
    let inside = hits * 10 >= PROBE_RAYS * 6 && backs * 10 < hits * 6;
    let view = if inside {
        inside_view(&rays, center, lo, hi, size)
    } else {
        outside_view(&tris, center, lo, hi)
    };
    let (light, sun) = if inside {
        inside_light(&rays, &probe::sphere(SKY_RAYS), &view, size)
    } else {
        (outside_light(&view), false)
    };
    let camera = Camera::look_at(
        view.eye.as_vec3(),
        view.target.as_vec3(),
        glam::Vec3::Y,
        (view.fov as f32).to_radians(),
        view.znear as f32,
    );
    let mut said = Vec::new();
    let mut keep = Vec::new();
    let digits = decimals(size);
    let at = |p: DVec3| triple(scene.origin + p, digits);
    if scene.bare.camera {
        scene.camera = camera;
        said.push(if inside {
            "a camera standing inside, looking along its length"
        } else {
            "a camera framing it from outside"
        });
        keep.push(format!(
            "--camera position={}:target={}:fov={}:znear={}",
            at(view.eye),
            at(view.target),
            view.fov,
            number(view.znear, digits + 2)
        ));
    }
    if scene.bare.light {
        scene.lights = vec![light];
        said.push(match (inside, sun) {
            (true, true) => "a sun through the opening above",
            (true, false) => "a spot light under the ceiling",
            _ => "a spot light above it",
        });
        keep.push(light_spec(&light, scene.origin, digits));
    }
    scene.bare = Default::default();
    let line = format!(
        "the scene has no {}: placed {} ({} of {} rays from its centre hit surfaces); keep or change them with {}",
        match (said.len(), keep[0].starts_with("--camera")) {
            (2, _) => "camera or light",
            (_, true) => "camera",
            _ => "light",
        },
        said.join(" and "),
        hits,
        PROBE_RAYS,
        keep.join(" ")
    );
    Some(Placed { inside, sun, line })
}

/// Where the camera stands and looks.
struct View {
    eye: DVec3,
    target: DVec3,
    fov: f64,
    znear: f64,
}

/// Inside: at a third of the height above the floor below the centre, near
/// the end of the longest horizontal axis, looking along it.
fn inside_view(rays: &Rays, center: DVec3, lo: DVec3, hi: DVec3, size: f64) -> View {
    let floor = rays
        .cast(center, -DVec3::Y)
        .map_or(lo.y, |f| center.y - f.t);
    let ceiling = rays.cast(center, DVec3::Y).map_or(hi.y, |f| center.y + f.t);
    let height = (ceiling - floor).max(size * 1e-3);
    let eye_y = floor + height / 3.0;
    let extent = hi - lo;
    let axis = if extent.x >= extent.z {
        DVec3::X
    } else {
        DVec3::Z
    };
    let half = 0.5 * extent.dot(axis);
    let start = DVec3::new(center.x, eye_y, center.z);
    // Back from the centre toward one end, short of the wall or column
    // that a ray that way meets.
    let back = rays.cast(start, -axis).map_or(half, |f| f.t.min(half));
    let eye = start - axis * (0.8 * back);
    let ahead = rays.cast(start, axis).map_or(half, |f| f.t.min(half));
    let target = start + axis * ahead - DVec3::Y * (0.1 * height);
    View {
        eye,
        target,
        fov: 60.0,
        znear: size * 1e-3,
    }
}

/// Outside: the side (eight around, two heights) that shows the most
/// surface, at the distance that frames the bounds in a 45 degree view.
fn outside_view(tris: &[[DVec3; 3]], center: DVec3, lo: DVec3, hi: DVec3) -> View {
    let radius = ((hi - lo).length() * 0.5)
        .max(center.abs().max_element() * 1e-6)
        .max(f64::MIN_POSITIVE);
    let mut best = (f64::NEG_INFINITY, DVec3::Z);
    for elevation in [20f64, 50.0] {
        for k in 0..8 {
            let azimuth = (k as f64 * 45.0).to_radians();
            let e = elevation.to_radians();
            let v = DVec3::new(azimuth.sin() * e.cos(), e.sin(), azimuth.cos() * e.cos());
            let seen = probe::seen_area(tris, v);
            // Ties (a sphere) keep the first: from +Z, low.
            if seen > best.0 * 1.02 {
                best = (seen, v);
            }
        }
    }
    let fov = 45f64;
    // Near enough that the bounds' corners just fit a square view (wider
    // images see more at the sides), by the corner that needs the most.
    let v = best.1;
    let right = DVec3::Y.cross(v).normalize_or(DVec3::X);
    let up = v.cross(right);
    let tan = (fov.to_radians() * 0.5).tan();
    let mut distance = f64::MIN_POSITIVE;
    for i in 0..8 {
        let pick = |bit: usize, a: f64, b: f64| if i & bit != 0 { b } else { a };
        let c = DVec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        ) - center;
        let across = c.dot(right).abs().max(c.dot(up).abs());
        distance = distance.max(1.05 * across / tan + c.dot(v));
    }
    let distance = distance.max(radius * 1e-3);
    View {
        eye: center + v * distance,
        target: center,
        fov,
        znear: (distance - radius).max(distance * 1e-3),
    }
}

/// A spot above and to the side of the camera (40 degrees round, 55 up
/// from the centre), never in the plane of a flat scene the camera faces.
fn outside_light(view: &View) -> Light {
    let to_eye = view.eye - view.target;
    let distance = to_eye.length();
    let flat = DVec3::new(to_eye.x, 0.0, to_eye.z).normalize_or(DVec3::Z);
    let turned = glam::DQuat::from_rotation_y(40f64.to_radians()) * flat;
    let e = 55f64.to_radians();
    let from = (turned * e.cos() + DVec3::Y * e.sin()).normalize();
    let d = distance * 1.2;
    // Half of the view's cone, then some, covers what the camera frames.
    let radius = distance * (view.fov.to_radians() * 0.5).sin();
    let cone = (radius / d).asin() + 10f64.to_radians();
    spot(view.target + from * d, view.target, cone, d)
}

/// A spot at `position` toward `target`, `cone` radians, bright enough
/// that a white surface at distance `d` facing it reflects radiance 1.
fn spot(position: DVec3, target: DVec3, cone: f64, d: f64) -> Light {
    Light {
        kind: LightKind::Spot,
        position: position.as_vec3(),
        direction: (target - position).normalize().as_vec3(),
        color: glam::Vec3::ONE,
        intensity: (std::f64::consts::PI * d * d).clamp(f32::MIN_POSITIVE as f64, f32::MAX as f64)
            as f32,
        inner_cone: (cone * 0.75) as f32,
        outer_cone: cone as f32,
        range: None,
    }
}

/// Inside: a sun down through an opening above the middle of the floor,
/// when rays from there escape upward; else a spot under the ceiling.
fn inside_light(rays: &Rays, dirs: &[DVec3], view: &View, size: f64) -> (Light, bool) {
    let mid = (view.eye + view.target) * 0.5;
    let floor_y = rays
        .cast(mid, -DVec3::Y)
        .map_or(view.eye.y, |f| mid.y - f.t);
    let floor = DVec3::new(mid.x, floor_y + size * 1e-3, mid.z);
    // Up directions at least 30 degrees above the horizon that escape,
    // each with its neighbours (within 6 degrees: Sponza's roof opening
    // is 28 degrees wide seen from its floor) escaping too, so that the
    // sun comes through an opening, not a crack.
    let up: Vec<DVec3> = dirs.iter().copied().filter(|d| d.y > 0.5).collect();
    let free: Vec<bool> = up.iter().map(|&d| rays.cast(floor, d).is_none()).collect();
    let cos6 = 6f64.to_radians().cos();
    let open = up
        .iter()
        .zip(&free)
        .filter(|(d, &f)| f && up.iter().zip(&free).all(|(e, &g)| g || d.dot(*e) < cos6))
        .map(|(d, _)| *d)
        // The highest such direction: the sun stands as high as the
        // opening lets it, so the floor is lit and the walls get its bounce.
        .max_by(|a, b| a.y.total_cmp(&b.y));
    if let Some(d) = open {
        let sun = Light {
            kind: LightKind::Directional,
            position: floor.as_vec3(),
            direction: (-d).as_vec3(),
            color: glam::Vec3::ONE,
            intensity: std::f32::consts::PI,
            inner_cone: 0.0,
            outer_cone: std::f32::consts::FRAC_PI_2,
            range: None,
        };
        return (sun, true);
    }
    let ceiling = rays
        .cast(floor, DVec3::Y)
        .map_or(view.eye.y + size * 0.5, |f| floor.y + f.t);
    let drop = ceiling - floor.y;
    let position = DVec3::new(floor.x, floor.y + 0.95 * drop, floor.z);
    (
        spot(position, floor, 70f64.to_radians(), 0.95 * drop),
        false,
    )
}

/// Decimals that give about four significant digits at `size`.
fn decimals(size: f64) -> usize {
    (3 - size.log10().floor() as i64).clamp(0, 12) as usize
}

fn number(v: f64, digits: usize) -> String {
    let s = format!("{v:.digits$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

fn triple(p: DVec3, digits: usize) -> String {
    format!(
        "{},{},{}",
        number(p.x, digits),
        number(p.y, digits),
        number(p.z, digits)
    )
}

/// The `--light` that gives `l` (in world coordinates: `origin` added).
fn light_spec(l: &Light, origin: DVec3, digits: usize) -> String {
    let pos = origin + l.position.as_dvec3();
    match l.kind {
        LightKind::Directional => format!(
            "--light directional:direction={}:intensity={}",
            triple(l.direction.as_dvec3(), 4),
            number(l.intensity as f64, 4)
        ),
        _ => {
            let d = (l.intensity as f64 / std::f64::consts::PI).sqrt();
            format!(
                "--light spot:position={}:target={}:cone={}:inner={}:intensity={}",
                triple(pos, digits),
                triple(pos + l.direction.as_dvec3() * d, digits),
                number((l.outer_cone as f64).to_degrees(), 2),
                number((l.inner_cone as f64).to_degrees(), 2),
                number(l.intensity as f64, 4)
            )
        }
    }
}
