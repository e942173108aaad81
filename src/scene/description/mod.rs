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

use super::animation::{Animation, Parent};
use super::gltf_load::{fitted_camera, fitted_light, LoadOptions};
use super::obj_load::files;
use super::{FileKind, Scene};
use anyhow::{anyhow, bail, Context as _, Result};
use glam::{Mat4, Vec3};
use lights::{add_path, camera, light};
pub use options::{parse_camera, parse_light};

mod lights;
mod options;
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

/// A light as a description or `--light` gives it. Places (position,
/// target, an orbit's centre) are world metres in f64: a scene stored
/// relative to an origin of its own (`Scene::origin`) gets them relative
/// to it, rounded to f32 only then.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default)]
    pub position: Option<[f64; 3]>,
    #[serde(default)]
    pub target: Option<[f64; 3]>,
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
    pub position: Option<[f64; 3]>,
    #[serde(default)]
    pub target: Option<[f64; 3]>,
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
    pub position: Option<[f64; 3]>,
    #[serde(default)]
    pub target: Option<[f64; 3]>,
    #[serde(default)]
    pub direction: Option<[f32; 3]>,
}

/// Circling the vertical axis through `center`.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Orbit {
    pub period: f32,
    #[serde(default)]
    pub center: Option<[f64; 3]>,
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
    // A byte-order mark (editors on Windows write one) is no JSON value.
    let bytes = super::text::strip_bom(bytes);
    let d: Description = serde_json::from_slice(bytes).map_err(|e| {
        let at = format!(" at line {} column {}", e.line(), e.column());
        let message = e.to_string();
        // serde's message quotes the file (an unknown field's name, a
        // string of the wrong type): escaped and cut like any file text.
        anyhow!(
            "line {} column {}: {} (the format: README, \"Scenes from the archives\")",
            e.line(),
            e.column(),
            super::text::quote_at_most(message.strip_suffix(&at).unwrap_or(&message), 300)
        )
    })?;
    let folder = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let allow = options.allow_outside_uris;
    let mesh = match &d.mesh {
        serde_json::Value::String(name) => files::resolve(name, Path::new(""), &folder, allow)
            .with_context(|| format!("mesh {}", super::text::quote(name)))?,
        serde_json::Value::Object(o) if o.len() == 1 && o.get("archive").is_some_and(|v| v.is_string()) => {
            let name = o["archive"].as_str().unwrap_or_default();
            let root = archive_root();
            if !root.is_dir() {
                bail!("mesh {{\"archive\": \"{}\"}}: {} is not a folder; {}", super::text::quote(name), root.display(), archive_hint());
            }
            files::resolve(name, Path::new(""), &root, allow).with_context(|| {
                format!("mesh {{\"archive\": \"{}\"}} in {} ({})", super::text::quote(name), root.display(), archive_hint())
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
            (scene.origin + l.position.as_dvec3()).to_array(),
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
    // A description places what it leaves out as it always did.
    scene.bare = super::Bare::default();
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
            let (light, motion) =
                light(spec, pivot, scene.origin).with_context(|| label.clone())?;
            scene.lights.push(light);
            if let Some(keys) = motion {
                let node = add_path(&mut animation, &keys).with_context(|| label.clone())?;
                animation.attach_light(i, node);
            }
        }
    }
    if let Some(c) = camera {
        animation.camera = None;
        let (cam, motion) = self::camera(c, pivot, diagonal, scene.origin).context("camera")?;
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
        _ => bail!(
            "up '{}': the file's up axis is one of +y, -y, +z, -z, +x, -x",
            super::text::quote(up)
        ),
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
    // The scene's own origin is placed too (a rotation and a scale: no
    // translation), in f64.
    scene.origin = m.as_dmat4().transform_point3(scene.origin);
}

/// The coordinate budget and the smallest scene, after placement.
fn check_reach(scene: &Scene, options: &LoadOptions) -> Result<()> {
    let (lo, hi) = scene
        .bounds()
        .ok_or_else(|| anyhow!("the mesh has no vertices"))?;
    let o = scene.origin;
    let reach = ((o + lo.as_dvec3()).abs())
        .max((o + hi.as_dvec3()).abs())
        .max_element() as f32;
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
