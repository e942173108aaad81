//! Scene descriptions (`NAME.scene.json`): lights, a camera and motion for a
//! mesh file that has none (an OBJ from the archives), without editing it.
//! Accepted wherever `--scene` is (`isr render`, `view`, `bench`); the
//! command line's `--light` and `--camera` take the same lights and camera
//! in a short form ([`parse_light`], [`parse_camera`]).
//!
//! ```json
//! {
//!   "mesh": "sponza.obj",
//!   "scale": 1.0, "up": "+y",
//!   "albedo": [0.8, 0.8, 0.8],
//!   "room": {"size": [4, 3, 4], "albedo": 0.7},
//!   "lights": [
//!     {"type": "spot", "position": [0, 9, 0], "target": [0, 0, 0], "cone": 40,
//!      "intensity": 300,
//!      "path": [{"t": 0, "position": [-8, 9, 0]}, {"t": 4, "position": [8, 9, 0]}]},
//!     {"type": "directional", "direction": [0.3, -1, 0.2], "intensity": 3,
//!      "path": [{"t": 0, "direction": [-0.5, -1, 0.1]}, {"t": 4, "direction": [0.5, -1, 0.1]}]},
//!     {"type": "point", "position": [1, 2, 0], "orbit": {"period": 8}}
//!   ],
//!   "camera": {"position": [-10, 2, 0], "target": [0, 3, 0], "fov": 60, "znear": 0.05,
//!              "path": [{"t": 0, "position": [-10, 2, 0]}, {"t": 4, "position": [-6, 2, 1]}]}
//! }
//! ```
//!
//! - `mesh`: an `.obj`, `.gltf` or `.glb` file, relative to the
//!   description's folder and held to the loader's policy: inside that
//!   folder unless `--allow-outside-uris`. Or `{"archive": "sponza/sponza.obj"}`:
//!   inside the folder of the archive scenes ([`archive_root`]: `ISR_SCENES`,
//!   or `../shared/scenes` beside the repository), which the user chose by
//!   that variable, and not outside it. The mesh's own files (an OBJ's MTL
//!   and textures, a glTF's buffers) are confined to the mesh's folder.
//! - `scale` (metres per file unit, default 1) and `up` (the file's up axis,
//!   `+y` default, `+z`, `-z`, `+x`, `-x`, `-y`) place the mesh: it is
//!   scaled and turned so that its up is +Y. Everything else is given in
//!   that frame, in metres.
//! - `albedo`: faces without a material (an OBJ without MTL); default 0.8.
//! - `room`: a floor under the mesh (at its lowest point) and three walls
//!   around it (`size` = width x, height y, depth z; open toward +z and at
//!   the top; single-sided, facing in), centred on the mesh; `albedo`.
//! - `lights` (replace the mesh's; none: the mesh's own, or the default
//!   spot): `type` spot, point or directional; `position`; `target` (a
//!   spot's aim) or `direction` (a directional light's rays); `intensity`
//!   (cd read as W/sr for spot and point lights, lux read as W/m^2 for
//!   directional ones; default: what makes a white surface facing the light
//!   at the target, or at the scene's centre, reflect radiance 1);
//!   `color`; `cone` and `inner_cone` (degrees, a spot's outer and inner
//!   half-angles, default 45 and 3/4 of the outer); `range`.
//! - `camera` (replaces the mesh's): `position`, `target`, `fov` (vertical,
//!   degrees, default 45), `znear` (metres, default 1/1000 of the scene's
//!   diagonal).
//! - Motion, for a light or the camera: `path`, keyframes `{"t", "position",
//!   "target"}` (a directional light: `{"t", "direction"}`; omitted fields
//!   keep the previous key's), played linearly by the glTF animation
//!   machinery (`scene::animation`; time clamps after the last key); or
//!   `orbit` `{"period", "center", "turns"}`: circling the vertical axis
//!   through `center` (default the scene's centre) `turns` times (default
//!   1), still aimed at the target.

use super::animation::{
    rotation_looking_along, Animation, Channel, Interpolation, Local, Parent, Property, Trs,
};
use super::gltf_load::{fitted_camera, fitted_light, LoadOptions};
use super::obj_load::files;
use super::{Camera, FileKind, Light, LightKind, Scene};
use anyhow::{anyhow, bail, Context as _, Result};
use glam::{Mat4, Vec3, Vec4};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The environment variable naming the folder of the archive scenes.
pub const ARCHIVE_VARIABLE: &str = "ISR_SCENES";

/// The folder of the archive scenes: `$ISR_SCENES`, or else `../shared/scenes`
/// beside the repository this binary was built from.
pub fn archive_root() -> PathBuf {
    match std::env::var_os(ARCHIVE_VARIABLE) {
        Some(v) if !v.is_empty() => PathBuf::from(v),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/scenes"),
    }
}

/// How to get the archive scenes, for errors that miss them.
pub fn archive_hint() -> String {
    format!(
        "the archive scenes (Sibenik, Sponza, the conference room, the bunny) are read from {}; \
         set {ARCHIVE_VARIABLE} to the folder that holds sibenik/, sponza/, conference/ and bunny/ \
         (README, \"Scenes from the archives\")",
        archive_root().display()
    )
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Description {
    mesh: serde_json::Value,
    #[serde(default = "one")]
    scale: f64,
    #[serde(default)]
    up: Option<String>,
    #[serde(default)]
    albedo: Option<[f32; 3]>,
    #[serde(default)]
    room: Option<Room>,
    #[serde(default)]
    lights: Vec<LightSpec>,
    #[serde(default)]
    camera: Option<CameraSpec>,
}

fn one() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Room {
    size: [f32; 3],
    #[serde(default)]
    albedo: Option<serde_json::Value>,
}

/// A light as a description or `--light` gives it.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default)]
    pub position: Option<[f32; 3]>,
    #[serde(default)]
    pub target: Option<[f32; 3]>,
    #[serde(default)]
    pub direction: Option<[f32; 3]>,
    #[serde(default)]
    pub intensity: Option<f32>,
    #[serde(default)]
    pub color: Option<[f32; 3]>,
    /// Degrees.
    #[serde(default)]
    pub cone: Option<f32>,
    /// Degrees.
    #[serde(default)]
    pub inner_cone: Option<f32>,
    #[serde(default)]
    pub range: Option<f32>,
    #[serde(default)]
    pub path: Option<Vec<Key>>,
    #[serde(default)]
    pub orbit: Option<Orbit>,
}

/// The camera as a description or `--camera` gives it.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    #[serde(default)]
    pub position: Option<[f32; 3]>,
    #[serde(default)]
    pub target: Option<[f32; 3]>,
    /// Vertical field of view, degrees.
    #[serde(default)]
    pub fov: Option<f32>,
    #[serde(default)]
    pub znear: Option<f32>,
    #[serde(default)]
    pub path: Option<Vec<Key>>,
    #[serde(default)]
    pub orbit: Option<Orbit>,
}

/// One keyframe of a path.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Key {
    pub t: f32,
    #[serde(default)]
    pub position: Option<[f32; 3]>,
    #[serde(default)]
    pub target: Option<[f32; 3]>,
    #[serde(default)]
    pub direction: Option<[f32; 3]>,
}

/// Circling the vertical axis through `center`.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Orbit {
    pub period: f32,
    #[serde(default)]
    pub center: Option<[f32; 3]>,
    #[serde(default)]
    pub turns: Option<f32>,
}

/// Loads the description `path` and the mesh it names.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let (file, _) = files::open_regular(path, options.limits.description_bytes)
        .map_err(|e| anyhow!("cannot read scene file {}: {e:#}", path.display()))?;
    let mut bytes = Vec::new();
    use std::io::Read as _;
    file.take(options.limits.description_bytes + 1)
        .read_to_end(&mut bytes)
        .with_context(|| format!("cannot read scene file {}", path.display()))?;
    load_bytes(path, &bytes, options)
        .with_context(|| format!("loading scene description {}", path.display()))
}

/// Loads a description from `bytes` as if read from `path` (its folder is
/// where a relative `mesh` is looked for).
pub fn load_bytes(path: &Path, bytes: &[u8], options: &LoadOptions) -> Result<Scene> {
    if bytes.len() as u64 > options.limits.description_bytes {
        bail!(
            "the scene description is {}, more than the limit of {}",
            super::limits::bytes(bytes.len() as u64),
            super::limits::bytes(options.limits.description_bytes)
        );
    }
    let d: Description = serde_json::from_slice(bytes).map_err(|e| {
        let at = format!(" at line {} column {}", e.line(), e.column());
        let message = e.to_string();
        anyhow!(
            "line {} column {}: {} (the format: README, \"Scenes from the archives\")",
            e.line(),
            e.column(),
            message.strip_suffix(&at).unwrap_or(&message)
        )
    })?;
    let folder = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let allow = options.allow_outside_uris;
    let mesh = match &d.mesh {
        serde_json::Value::String(name) => files::resolve(name, Path::new(""), &folder, allow)
            .with_context(|| format!("mesh {name}"))?,
        serde_json::Value::Object(o) if o.len() == 1 && o.get("archive").is_some_and(|v| v.is_string()) => {
            let name = o["archive"].as_str().unwrap_or_default();
            let root = archive_root();
            if !root.is_dir() {
                bail!("mesh {{\"archive\": {name:?}}}: {} is not a folder; {}", root.display(), archive_hint());
            }
            files::resolve(name, Path::new(""), &root, allow).with_context(|| {
                format!("mesh {{\"archive\": {name:?}}} in {} ({})", root.display(), archive_hint())
            })?
        }
        other => bail!(
            "\"mesh\" must be a file name (relative to the description) or {{\"archive\": \"folder/file.obj\"}}, not {other}"
        ),
    };
    let albedo = match d.albedo {
        Some(a) => checked_albedo(a, "albedo")?,
        None => Vec3::splat(super::obj_load::DEFAULT_ALBEDO),
    };
    let mut scene = match FileKind::of(&mesh) {
        FileKind::Obj => super::obj_load::load_mesh(&mesh, options, albedo)?,
        FileKind::Gltf => super::gltf_load::load_with(&mesh, options)?,
        FileKind::Description => {
            bail!(
                "mesh {}: a description names an OBJ or glTF file, not another description",
                mesh.display()
            )
        }
    };
    if let Some(stem) = path.file_name().and_then(|n| n.to_str()) {
        scene.name = stem
            .strip_suffix(".json")
            .unwrap_or(stem)
            .trim_end_matches(".scene")
            .to_string();
    }
    let is_obj = FileKind::of(&mesh) == FileKind::Obj;
    if !(d.scale.is_finite() && d.scale > 0.0 && (d.scale as f32).is_normal()) {
        bail!(
            "scale {}: metres per file unit must be a positive number",
            d.scale
        );
    }
    let turn = up_rotation(d.up.as_deref().unwrap_or("+y"))?;
    let placement = Mat4::from_quat(turn) * Mat4::from_scale(Vec3::splat(d.scale as f32));
    place(&mut scene, placement, d.scale as f32);
    if let Some(room) = &d.room {
        add_room(&mut scene, room)?;
    }
    check_reach(&scene, options)?;
    let (lo, hi) = scene
        .bounds()
        .ok_or_else(|| anyhow!("the mesh has no vertices"))?;
    if d.lights.is_empty() && is_obj {
        let l = fitted_light(lo, hi);
        scene.warnings.push(format!(
            "the description has no lights: using a default spot light at {:.2?} pointing down (60 degree cone, {:.1} cd)",
            l.position.to_array(),
            l.intensity
        ));
        scene.lights = vec![l];
    }
    if d.camera.is_none() && is_obj {
        scene.camera = fitted_camera(lo, hi);
        scene.warnings.push(
            "the description has no camera: using a default camera on +Z looking at the scene's center".into(),
        );
    }
    let lights: Vec<(String, LightSpec)> = d
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| (format!("light {i}"), l.clone()))
        .collect();
    apply(&mut scene, &lights, d.camera.as_ref())?;
    Ok(scene)
}

/// Replaces the lights of `scene` (when `lights` is not empty) and its
/// camera (when given), each with its motion; what the scene's animation
/// did to what is replaced no longer applies. Each light is named by its
/// label in errors (`--light 2`, `light 0`).
pub fn apply(
    scene: &mut Scene,
    lights: &[(String, LightSpec)],
    camera: Option<&CameraSpec>,
) -> Result<()> {
    let (lo, hi) = scene
        .bounds()
        .ok_or_else(|| anyhow!("the scene has no geometry to place lights and a camera by"))?;
    let pivot = (lo + hi) * 0.5;
    let diagonal = (hi - lo).length();
    let mut animation = scene.animation.take().unwrap_or_default();
    if !lights.is_empty() {
        animation.lights.clear();
        scene.lights.clear();
        for (i, (label, spec)) in lights.iter().enumerate() {
            let (light, motion) = light(spec, pivot).with_context(|| label.clone())?;
            scene.lights.push(light);
            if let Some(keys) = motion {
                let node = add_path(&mut animation, &keys).with_context(|| label.clone())?;
                animation.attach_light(i, node);
            }
        }
    }
    if let Some(c) = camera {
        animation.camera = None;
        let (cam, motion) = self::camera(c, pivot, diagonal).context("camera")?;
        scene.camera = cam;
        if let Some(keys) = motion {
            let node = add_path(&mut animation, &keys).context("camera")?;
            animation.attach_camera(node);
        }
    }
    scene.animation = (animation != Animation::default()).then_some(animation);
    // Every pose the motion gives is checked where the renderer meets it
    // (`Scene::pose_at`); the rest pose here.
    scene.pose_at(0.0)?;
    Ok(())
}

/// The rotation that turns the file's `up` axis to +Y.
fn up_rotation(up: &str) -> Result<glam::Quat> {
    use std::f32::consts::FRAC_PI_2;
    Ok(match up.trim().to_ascii_lowercase().as_str() {
        "+y" | "y" => glam::Quat::IDENTITY,
        "-y" => glam::Quat::from_rotation_x(std::f32::consts::PI),
        "+z" | "z" => glam::Quat::from_rotation_x(-FRAC_PI_2),
        "-z" => glam::Quat::from_rotation_x(FRAC_PI_2),
        "+x" | "x" => glam::Quat::from_rotation_z(FRAC_PI_2),
        "-x" => glam::Quat::from_rotation_z(-FRAC_PI_2),
        other => bail!("up {other:?}: the file's up axis is one of +y, -y, +z, -z, +x, -x"),
    })
}

/// Places the whole scene by `m` (a rotation times the uniform `scale`):
/// instances, the animation's roots, lights and the camera (whose znear
/// scales with it).
fn place(scene: &mut Scene, m: Mat4, scale: f32) {
    if m == Mat4::IDENTITY {
        return;
    }
    for inst in &mut scene.instances {
        inst.world_from_object = m * inst.world_from_object;
    }
    if let Some(a) = &mut scene.animation {
        for node in &mut a.nodes {
            if let Parent::Fixed(p) = &mut node.parent {
                *p = m * *p;
            }
        }
    }
    for l in &mut scene.lights {
        l.position = m.transform_point3(l.position);
        l.direction = m.transform_vector3(l.direction).normalize_or(l.direction);
        // Intensities stay: a scene scaled by s with intensities times s^2
        // renders the same (README, "Scale and precision").
    }
    let c = &mut scene.camera;
    if let Some(w) = super::rigid(m * c.world_from_camera) {
        c.world_from_camera = w;
    }
    c.znear *= scale;
}

/// The coordinate budget and the smallest scene, after placement.
fn check_reach(scene: &Scene, options: &LoadOptions) -> Result<()> {
    let (lo, hi) = scene
        .bounds()
        .ok_or_else(|| anyhow!("the mesh has no vertices"))?;
    let reach = lo.abs().max(hi.abs()).max_element();
    let limits = &options.limits;
    if reach.is_nan() || reach > limits.coordinate {
        bail!(
            "placed by the description, the scene reaches {reach:.3e} m from the origin; isr supports coordinates up to {:.0e} m (a smaller scale?)",
            limits.coordinate
        );
    }
    if (hi - lo).length() < limits.min_extent {
        bail!(
            "placed by the description, the scene spans {:.3e} m; isr supports scenes at least {:.0e} m across (a larger scale?)",
            (hi - lo).length(),
            limits.min_extent
        );
    }
    Ok(())
}

fn checked_albedo(a: [f32; 3], what: &str) -> Result<Vec3> {
    let v = Vec3::from(a);
    if !(v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= 1.0) {
        bail!("{what} {a:?}: an albedo is three numbers from 0 to 1");
    }
    Ok(v)
}

/// A floor at the mesh's lowest point and three walls around it.
fn add_room(scene: &mut Scene, room: &Room) -> Result<()> {
    let size = Vec3::from(room.size);
    if !(size.is_finite() && size.min_element() > 0.0) {
        bail!(
            "room size {:?}: width, height and depth must be positive",
            room.size
        );
    }
    let albedo = match &room.albedo {
        None => Vec3::splat(0.7),
        Some(serde_json::Value::Number(n)) => {
            let g = n.as_f64().unwrap_or(f64::NAN) as f32;
            checked_albedo([g; 3], "room albedo")?
        }
        Some(v) => {
            let a: [f32; 3] = serde_json::from_value(v.clone())
                .map_err(|_| anyhow!("room albedo {v}: a number or three numbers from 0 to 1"))?;
            checked_albedo(a, "room albedo")?
        }
    };
    let (lo, hi) = scene
        .bounds()
        .ok_or_else(|| anyhow!("the mesh has no vertices"))?;
    let c = (lo + hi) * 0.5;
    let (x0, x1) = (c.x - size.x * 0.5, c.x + size.x * 0.5);
    let (z0, z1) = (c.z - size.z * 0.5, c.z + size.z * 0.5);
    let (y0, y1) = (lo.y, lo.y + size.y);
    let m = scene.add_material("room", albedo);
    let v = Vec3::new;
    scene.add_quad(
        "room floor",
        [v(x0, y0, z1), v(x1, y0, z1), v(x1, y0, z0), v(x0, y0, z0)],
        m,
    );
    scene.add_quad(
        "room back",
        [v(x0, y0, z0), v(x1, y0, z0), v(x1, y1, z0), v(x0, y1, z0)],
        m,
    );
    scene.add_quad(
        "room left",
        [v(x0, y0, z1), v(x0, y0, z0), v(x0, y1, z0), v(x0, y1, z1)],
        m,
    );
    scene.add_quad(
        "room right",
        [v(x1, y0, z0), v(x1, y0, z1), v(x1, y1, z1), v(x1, y1, z0)],
        m,
    );
    Ok(())
}

fn vec3(a: [f32; 3], what: &str) -> Result<Vec3> {
    let v = Vec3::from(a);
    if !v.is_finite() {
        bail!("{what} {a:?} is not finite");
    }
    Ok(v)
}

/// A position, within the coordinate budget (`Limits::coordinate`).
fn point(a: [f32; 3], what: &str) -> Result<Vec3> {
    let v = vec3(a, what)?;
    let limit = super::limits::Limits::DEFAULT.coordinate;
    if v.abs().max_element() > limit {
        bail!("{what} {a:?} reaches beyond {limit:.0e} m, the largest coordinate isr supports");
    }
    Ok(v)
}

/// One keyframe resolved: time, position, where it points.
struct Pose {
    t: f32,
    position: Vec3,
    direction: Vec3,
}

fn light(spec: &LightSpec, pivot: Vec3) -> Result<(Light, Option<Vec<Pose>>)> {
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

fn camera(spec: &CameraSpec, pivot: Vec3, diagonal: f32) -> Result<(Camera, Option<Vec<Pose>>)> {
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
                    super::motion::aim_point(rest.position, rest.direction, center)
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
fn add_path(a: &mut Animation, keys: &[Pose]) -> Result<usize> {
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
            "position" | "pos" => l.position = Some(vector(key, value)?),
            "target" => l.target = Some(vector(key, value)?),
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
    light(&l, Vec3::ZERO).map_err(|e| format!("{e:#}"))?;
    Ok(l)
}

/// `--camera`: `KEY=VALUE:...`, keys `position` (`pos`), `target`, `fov`
/// (vertical, degrees), `znear` (metres).
pub fn parse_camera(s: &str) -> Result<CameraSpec, String> {
    let mut c = CameraSpec::default();
    for part in s.split(':') {
        let (key, value) = key_value(part)?;
        match key {
            "position" | "pos" => c.position = Some(vector(key, value)?),
            "target" => c.target = Some(vector(key, value)?),
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
    camera(&c, Vec3::ZERO, 1.0).map_err(|e| format!("{e:#}"))?;
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
