//! Wavefront OBJ + MTL (`.obj`) to [`Scene`], read by isr line by line:
//! polygons fanned into triangles, one mesh per material, `Kd` times
//! `map_Kd` (PNG or JPEG, sRGB) as the Lambertian albedo, normals computed
//! where the file has none (with a crease angle, `normals`), degenerate
//! faces skipped and counted.
//!
//! The same policy as the glTF loader (docs/security.md): the OBJ's
//! libraries and textures only from inside its folder unless
//! `LoadOptions::allow_outside_uris`, regular files only, every size and
//! count budget of [`Limits`] checked at the line that passes it, before
//! the work it bounds. The file is checked to be within `scene_file_bytes`
//! before it is opened, then read one line at a time (`check`), each line
//! adding to the geometry and to the mesh of its material (`assemble`), so
//! memory grows with what the file defines, never with how often it names
//! a library, a group or a material. Errors name the file and the line; a
//! warning is said once per kind, with a count (`tally`). An OBJ has no
//! lights or camera: the scene gets the default ones
//! (`gltf_load::fitted_light`, `fitted_camera`) with a warning, or those of
//! a scene description (`scene::description`) or the command line
//! (`--light`, `--camera`).
//!
//! Choices: every OBJ material is double-sided (the format has no culling
//! and archive models are not consistently wound); a face wound against
//! its normals is turned to agree with them; texture coordinates are
//! flipped to the top-left origin the GPU samples; a texture that is
//! missing or fails to decode is an error, as in a glTF, not the
//! material's `Kd` with a warning: a different albedo changes every
//! number measured on the scene, and a warning scrolls past unread.

use super::gltf_load::{fitted_camera, fitted_light, LoadOptions};
pub use super::limits::Limits;
use super::text::quote_at_most;
use super::{limits, Instance, Material, Mesh, Scene};
use anyhow::{anyhow, bail, Result};
use glam::{Vec3, Vec4};
use std::collections::HashMap;
use std::io::BufRead;
use std::path::{Path, PathBuf};

mod assemble;
mod check;
pub(super) mod files;
mod mtl;
pub mod normals;
mod tally;

/// Albedo of faces without a material (no `usemtl`, or a name no library
/// defines), and of a material without `Kd` or `map_Kd`.
pub const DEFAULT_ALBEDO: f32 = 0.8;

/// An index a face corner does not give (no texture coordinate, no normal).
const NONE: u32 = u32::MAX;

/// Loads an OBJ file with the default (safe) options.
pub fn load(path: &Path) -> Result<Scene> {
    load_with(path, &LoadOptions::default())
}

/// Loads an OBJ file: its size is checked first, then it is read line by
/// line. A panic (a bug: `load_bytes` is fuzzed to have none) becomes an
/// error naming the file.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scene> {
    load_mesh(path, options, Vec3::splat(DEFAULT_ALBEDO)).map(with_default_warnings)
}

/// [`load_with`] with `albedo` for faces without a material, and without
/// the warnings about the default light and camera (a scene description
/// places its own).
pub(in crate::scene) fn load_mesh(
    path: &Path,
    options: &LoadOptions,
    albedo: Vec3,
) -> Result<Scene> {
    let (file, _) = files::open_regular(path, options.limits.scene_file_bytes)
        .map_err(|e| anyhow!("cannot read scene file {}: {e:#}", display(path)))?;
    let reader = std::io::BufReader::with_capacity(1 << 16, file);
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        load_checked(path, reader, options, albedo)
    }));
    std::panic::set_hook(previous);
    match result {
        // Every error names the file once, with its line where it has one.
        Ok(r) => r.map(|(s, _)| s),
        Err(_) => bail!(
            "{}: the file is malformed in a way the OBJ reader could not handle",
            display(path)
        ),
    }
}

/// The file's name as messages show it.
fn display(path: &Path) -> String {
    quote_at_most(&path.display().to_string(), super::text::PATH_CHARS)
}

/// Loads an OBJ from `bytes` as if read from `path` (whose folder holds its
/// libraries and textures; `path` itself is not read). No panic guard.
pub fn load_bytes(path: &Path, bytes: &[u8], options: &LoadOptions) -> Result<Scene> {
    if bytes.len() as u64 > options.limits.scene_file_bytes {
        bail!(
            "the scene file is {}, more than the limit of {}",
            limits::bytes(bytes.len() as u64),
            limits::bytes(options.limits.scene_file_bytes)
        );
    }
    load_reader(path, bytes, options).map(|(s, _)| s)
}

/// The warnings that say an OBJ brings no light or camera and where the
/// defaults are.
fn with_default_warnings(mut scene: Scene) -> Scene {
    scene.bare = super::Bare {
        light: true,
        camera: true,
    };
    let light = scene.lights[0];
    scene.warnings.push(format!(
        "an OBJ has no lights: using a default spot light at {:.2?} pointing down (60 degree cone, {:.1} cd); place lights with --light or a scene description",
        light.position.to_array(),
        light.intensity
    ));
    scene.warnings.push(
        "an OBJ has no camera: using a default camera on +Z looking at the scene's center; place it with --camera or a scene description"
            .into(),
    );
    scene
}

/// Loads an OBJ read from `reader` as if it were `path`; returns the scene
/// and the bytes taken from the reader (a refused file is read no further
/// than the line that passed a budget).
pub fn load_reader(
    path: &Path,
    reader: impl BufRead,
    options: &LoadOptions,
) -> Result<(Scene, u64)> {
    let (scene, bytes) = load_checked(path, reader, options, Vec3::splat(DEFAULT_ALBEDO))?;
    Ok((with_default_warnings(scene), bytes))
}

fn load_checked(
    path: &Path,
    reader: impl BufRead,
    options: &LoadOptions,
    albedo: Vec3,
) -> Result<(Scene, u64)> {
    let base = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let mut st = State {
        display: display(path),
        name: path.file_name().map_or_else(
            || display(path),
            |n| super::text::quote(&n.to_string_lossy()),
        ),
        base,
        options: options.clone(),
        line: 0,
        geometry: Default::default(),
        triangles: 0,
        distinct: 0,
        meshes: Vec::new(),
        mesh_of: HashMap::new(),
        current: None,
        current_mesh: None,
        materials: Default::default(),
        tally: Default::default(),
    };
    let mut lines = check::Lines::new(reader);
    let max = options.limits.line_bytes;
    loop {
        st.line += 1;
        let raw = match lines.next(max) {
            Ok(Some(raw)) => raw,
            Ok(None) => break,
            Err(e) => return Err(e.context(st.at())),
        };
        check::line(raw, &mut st).map_err(|e| e.context(st.at()))?;
    }
    st.line -= 1;
    let bytes = lines.bytes;
    drop(lines);
    build(path, st, albedo).map(|s| (s, bytes))
}

/// What the lines read so far defined.
struct State {
    /// The OBJ file, for messages; and its name alone, for warnings.
    display: String,
    name: String,
    /// The scene's folder: libraries and textures are confined to it.
    base: PathBuf,
    options: LoadOptions,
    /// The line being read.
    line: u64,
    geometry: assemble::Geometry,
    /// Triangles the faces fan into, degenerate ones too.
    triangles: u64,
    /// Distinct vertices of all meshes.
    distinct: u64,
    /// One mesh per material, in the order first used.
    meshes: Vec<assemble::MeshBuilder>,
    mesh_of: HashMap<Option<u32>, usize>,
    /// The material of the faces that follow (`usemtl`), and its mesh.
    current: Option<u32>,
    current_mesh: Option<usize>,
    materials: mtl::Materials,
    tally: tally::Tally,
}

impl State {
    /// "scene.obj line N", for messages.
    fn at(&self) -> String {
        format!("{} line {}", self.display, self.line.max(1))
    }

    /// "scene.obj line N" with the file's name alone, for warnings, which
    /// list several places and are said after the file is named.
    fn here(&self) -> String {
        format!("{} line {}", self.name, self.line.max(1))
    }
}

/// The scene from the meshes read.
fn build(path: &Path, mut st: State, albedo: Vec3) -> Result<Scene> {
    let limits = st.options.limits;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let mut scene = Scene::empty(
        &name,
        fitted_light(Vec3::splat(-1.0), Vec3::ONE),
        fitted_camera(Vec3::splat(-1.0), Vec3::ONE),
    );
    let mut textures = mtl::Textures::default();
    let mut made = 0u64;
    for mesh in std::mem::take(&mut st.meshes) {
        let id = mesh.material;
        let left = limits.vertices.saturating_sub(made);
        let (vertices, indices) = assemble::finish(mesh, &st.geometry, left)
            .map_err(|e| e.context(st.display.clone()))?;
        made += vertices.len() as u64;
        if indices.is_empty() {
            continue;
        }
        let material = material(&mut scene, id, &st, &mut textures, albedo)
            .map_err(|e| e.context(st.display.clone()))?;
        scene.meshes.push(Mesh {
            name: scene.materials[material].name.clone(),
            vertices,
            indices,
            material,
        });
        scene.instances.push(Instance {
            mesh: scene.meshes.len() - 1,
            world_from_object: glam::Mat4::IDENTITY,
        });
    }
    if scene.instances.is_empty() {
        let degenerate = st.tally.degenerate;
        bail!(
            "{} has no faces to render{}",
            st.display,
            if degenerate > 0 {
                format!(" (all {degenerate} are degenerate)")
            } else {
                String::new()
            }
        );
    }
    let (lo, hi) = limits
        .check_extent(
            &scene,
            "scale the scene down, e.g. with \"scale\" in a scene description",
        )
        .map_err(|e| e.context(st.display.clone()))?;
    scene.warnings = warnings(&st, albedo);
    scene.lights = vec![fitted_light(lo, hi)];
    scene.camera = fitted_camera(lo, hi);
    Ok(scene)
}

/// One warning per kind, with its count and where it first happened.
fn warnings(st: &State, albedo: Vec3) -> Vec<String> {
    let t = &st.tally;
    let mut w = Vec::new();
    if t.degenerate > 0 {
        w.push(format!(
            "{} degenerate triangle(s) (zero area, or a vertex used twice) skipped",
            t.degenerate
        ));
    }
    if t.computed > 0 {
        w.push(format!(
            "normals computed for {} triangle(s) without them (crease angle {} degrees)",
            t.computed,
            normals::CREASE_DEGREES
        ));
    }
    let counted = [
        (&t.zero_normals, "normal(s) of zero length (vn 0 0 0) ignored: the faces using them get computed normals"),
        (&t.partial_normals, "face(s) name a normal at some corners only: their normals are computed"),
        (&t.rewound, "triangle(s) wound against their normals (vn) turned to agree with them, so that they shade by the file's normals from either side"),
        (&t.partial_texcoords, "face(s) name texture coordinates at some corners only: (0, 0) at the others"),
        (&t.duplicate_materials, "material(s) defined twice in one library: the last definition is used"),
        (&t.kd_above_one, "Kd value(s) above 1 (reflecting more light than they receive) clamped to 1"),
        (&t.map_options, "map_Kd option(s) ignored (the texture is read as it is)"),
    ];
    for (count, what) in counted {
        if count.count > 0 {
            w.push(format!("{} {what}: first at {}", count.count, count.first));
        }
    }
    if !t.ignored_statements.is_empty() {
        w.push(format!(
            "OBJ statements ignored{}",
            t.ignored_statements.said()
        ));
    }
    if !t.ignored_keys.is_empty() {
        w.push(format!("MTL keys ignored{}", t.ignored_keys.said()));
    }
    if !t.unknown_materials.is_empty() {
        w.push(format!(
            "usemtl names no material of the material libraries (albedo {albedo} there){}",
            t.unknown_materials.said()
        ));
    }
    w
}

/// The scene material for material `id` of the libraries (`None`: the default).
fn material(
    scene: &mut Scene,
    id: Option<u32>,
    st: &State,
    textures: &mut mtl::Textures,
    default: Vec3,
) -> Result<usize> {
    let (name, albedo, texture) = match id.and_then(|i| st.materials.list.get(i as usize)) {
        None => ("default".to_string(), default, None),
        Some(m) => {
            let texture = mtl::texture(m, st, textures, scene)?;
            // Kd absent: the texture as it is, or the default grey.
            let kd = m.kd.unwrap_or(Vec3::splat(if texture.is_some() {
                1.0
            } else {
                DEFAULT_ALBEDO
            }));
            (super::text::quote(&m.name), kd, texture)
        }
    };
    scene.materials.push(Material {
        name,
        base_color: Vec4::from((albedo, 1.0)),
        texture,
        double_sided: true,
    });
    Ok(scene.materials.len() - 1)
}
