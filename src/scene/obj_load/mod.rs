//! Wavefront OBJ + MTL (`.obj`) to [`Scene`]: polygons fanned into
//! triangles by tobj, `Kd` times `map_Kd` (PNG or JPEG, sRGB) as the
//! Lambertian albedo, normals computed where the file has none (with a
//! crease angle, `normals`), degenerate faces skipped and counted.
//!
//! The same policy as the glTF loader (docs/security.md): the OBJ's
//! libraries and textures only from inside its folder unless
//! `LoadOptions::allow_outside_uris`, regular files only, every size and
//! count budget of [`Limits`] checked before the work it bounds. The file is
//! checked to be within `scene_file_bytes` before it is opened, then read
//! one line at a time by [`check::Checked`], which counts vertices and
//! triangles against the budgets as lines arrive, so a file of 10^8 `v`
//! lines is refused after `vertices` of them without being read whole.
//! Errors name the file and the line. An OBJ has no lights or camera: the
//! scene gets the default ones (`gltf_load::fitted_light`, `fitted_camera`)
//! with a warning, or those of a scene description (`scene::description`)
//! or the command line (`--light`, `--camera`).
//!
//! Choices: every OBJ material is double-sided (the format has no culling
//! and archive models are not consistently wound); texture coordinates are
//! flipped to the top-left origin the GPU samples; a texture that is
//! missing or fails to decode is an error, as in a glTF, not the
//! material's `Kd` with a warning: a different albedo changes every
//! number measured on the scene, and a warning scrolls past unread.

use super::gltf_load::{fitted_camera, fitted_light, LoadOptions};
pub use super::limits::Limits;
use super::{limits, GpuVertex, Instance, Material, Mesh, Scene};
use anyhow::{anyhow, bail, Context as _, Result};
use glam::{Vec3, Vec4};
use std::cell::RefCell;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::io::BufRead;
use std::path::{Path, PathBuf};

mod check;
pub(super) mod files;
mod mtl;
pub mod normals;

/// Albedo of faces without a material (no `usemtl`, or a name no library
/// defines), and of a material without `Kd` or `map_Kd`.
pub const DEFAULT_ALBEDO: f32 = 0.8;

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
        .map_err(|e| anyhow!("cannot read scene file {}: {e:#}", path.display()))?;
    let reader = std::io::BufReader::with_capacity(1 << 16, file);
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        load_checked(path, reader, options, albedo)
    }));
    std::panic::set_hook(previous);
    match result {
        Ok(r) => r
            .map(|(s, _)| s)
            .with_context(|| format!("loading scene {}", path.display())),
        Err(_) => bail!(
            "loading scene {}: the file is malformed in a way the OBJ reader could not handle",
            path.display()
        ),
    }
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
    let state = RefCell::new(State {
        display: path.display().to_string(),
        base,
        options: options.clone(),
        ..Default::default()
    });
    let mut checked = check::Checked::new(reader, &state);
    let tobj_options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let parsed = tobj::load_obj_buf(&mut checked, &tobj_options, |name| {
        mtl::load_library(&state, name)
    });
    let bytes_read = checked.bytes;
    drop(checked);
    let mut st = state.into_inner();
    if let Some(e) = st.error.take() {
        return Err(e);
    }
    let (models, _) = parsed.map_err(|e| {
        anyhow!(
            "{} line {}: the OBJ reader (tobj) reports: {e}",
            st.display,
            st.line
        )
    })?;
    build(path, models, st, albedo).map(|s| (s, bytes_read))
}

/// What the line check and the library reader share while tobj parses.
#[derive(Default)]
struct State {
    /// The OBJ file, for messages.
    display: String,
    /// The scene's folder: libraries and textures are confined to it.
    base: PathBuf,
    options: LoadOptions,
    /// Lines read so far.
    line: u64,
    positions: u64,
    texcoords: u64,
    normals: u64,
    triangles: u64,
    /// The first error: the reader stops tobj when it is set.
    error: Option<anyhow::Error>,
    /// Statements ignored: key -> (first line, count, why).
    ignored: BTreeMap<String, (u64, u64, &'static str)>,
    /// MTL keys ignored: key -> (first "file line N", count, why).
    ignored_mtl: BTreeMap<String, (String, u64, &'static str)>,
    /// Material names the libraries read so far define.
    material_names: HashSet<String>,
    /// `usemtl` names no library defined: name -> (first line, count).
    unknown_materials: BTreeMap<String, (u64, u64)>,
    /// Every library's materials in tobj's order (its material ids).
    materials: Vec<mtl::MtlMaterial>,
    /// Libraries read, by resolved path.
    libraries: HashMap<PathBuf, mtl::Library>,
    library_bytes: u64,
    warnings: Vec<String>,
}

/// The scene from tobj's models.
fn build(path: &Path, models: Vec<tobj::Model>, mut st: State, albedo: Vec3) -> Result<Scene> {
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
    let mut warnings = std::mem::take(&mut st.warnings);
    let mut material_ids: HashMap<Option<usize>, usize> = HashMap::new();
    let mut textures = mtl::Textures::default();
    let (mut degenerate, mut vertices_total) = (0u64, 0u64);
    let (mut computed, mut dropped_uv, mut dropped_normals) = (0usize, Vec::new(), Vec::new());
    for model in models {
        let m = model.mesh;
        let n = m.positions.len() / 3;
        if m.indices.is_empty() {
            continue;
        }
        vertices_total += n as u64;
        if vertices_total > limits.vertices {
            bail!(
                "the faces make more than {} distinct vertices (position, texture coordinate, normal); the limit is {}",
                limits.vertices,
                limits.vertices
            );
        }
        // tobj gives a vertex a texture coordinate or normal only where the
        // face names one: unless every vertex of the object has one, they do
        // not line up with the positions.
        let uv_ok = m.texcoords.len() == 2 * n;
        let normals_ok = m.normals.len() == 3 * n;
        if !m.texcoords.is_empty() && !uv_ok {
            dropped_uv.push(model.name.clone());
        }
        if !m.normals.is_empty() && !normals_ok {
            dropped_normals.push(model.name.clone());
        }
        let vertices: Vec<GpuVertex> = (0..n)
            .map(|i| GpuVertex {
                position: [
                    m.positions[3 * i],
                    m.positions[3 * i + 1],
                    m.positions[3 * i + 2],
                ],
                normal: if normals_ok {
                    Vec3::from_slice(&m.normals[3 * i..3 * i + 3])
                        .normalize_or(Vec3::Y)
                        .to_array()
                } else {
                    [0.0; 3]
                },
                // OBJ's v grows upward; the GPU's rows start at the top.
                uv: if uv_ok {
                    [m.texcoords[2 * i], 1.0 - m.texcoords[2 * i + 1]]
                } else {
                    [0.0; 2]
                },
            })
            .collect();
        let mut indices = Vec::with_capacity(m.indices.len());
        for t in m.indices.chunks_exact(3) {
            let p = |k: usize| Vec3::from(vertices[t[k] as usize].position);
            let area2 = (p(1) - p(0)).cross(p(2) - p(0));
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || area2 == Vec3::ZERO {
                degenerate += 1;
                continue;
            }
            indices.extend_from_slice(t);
        }
        if indices.is_empty() {
            continue;
        }
        let (vertices, indices) = if normals_ok {
            (vertices, indices)
        } else {
            computed += indices.len() / 3;
            normals::crease_normals(&vertices, &indices)
        };
        let material = match material_ids.get(&m.material_id) {
            Some(&id) => id,
            None => {
                let id = material(&mut scene, m.material_id, &st, &mut textures, albedo)?;
                material_ids.insert(m.material_id, id);
                id
            }
        };
        scene.meshes.push(Mesh {
            name: model.name,
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
    let (lo, hi) = limits.check_extent(
        &scene,
        "scale the scene down, e.g. with \"scale\" in a scene description",
    )?;
    if degenerate > 0 {
        warnings.push(format!(
            "{degenerate} degenerate face(s) (zero area, or a vertex used twice) skipped"
        ));
    }
    if computed > 0 {
        warnings.push(format!(
            "normals computed for {computed} triangle(s) without them (crease angle {} degrees)",
            normals::CREASE_DEGREES
        ));
    }
    for (what, names) in [
        ("texture coordinates", dropped_uv),
        ("normals", dropped_normals),
    ] {
        if !names.is_empty() {
            warnings.push(format!(
                "{what} dropped for object(s) {}: some of their face vertices have none",
                names.join(", ")
            ));
        }
    }
    for (key, (line, count, why)) in &st.ignored {
        warnings.push(format!(
            "OBJ statement '{}' ignored ({why}): line {line}{}",
            check::short(key),
            more(*count)
        ));
    }
    for (key, (at, count, why)) in &st.ignored_mtl {
        warnings.push(format!(
            "MTL key '{}' ignored ({why}): {at}{}",
            check::short(key),
            more(*count)
        ));
    }
    for (name, (line, count)) in &st.unknown_materials {
        warnings.push(format!(
            "usemtl {} (line {line}{}) names no material of the material libraries: albedo {albedo}",
            check::short(name),
            more(*count)
        ));
    }
    let light = fitted_light(lo, hi);
    scene.lights = vec![light];
    scene.camera = fitted_camera(lo, hi);
    scene.warnings = warnings;
    Ok(scene)
}

/// ", and N more" for a count of N + 1 lines.
fn more(count: u64) -> String {
    if count > 1 {
        format!(" and {} more", count - 1)
    } else {
        String::new()
    }
}

/// The scene material for tobj's material id (`None`: the default).
fn material(
    scene: &mut Scene,
    id: Option<usize>,
    st: &State,
    textures: &mut mtl::Textures,
    default: Vec3,
) -> Result<usize> {
    let (name, albedo, texture) = match id.and_then(|i| st.materials.get(i)) {
        None => ("default".to_string(), default, None),
        Some(m) => {
            let texture = mtl::texture(m, st, textures, scene)?;
            // Kd absent: the texture as it is, or the default grey.
            let kd = m.kd.unwrap_or(Vec3::splat(if texture.is_some() {
                1.0
            } else {
                DEFAULT_ALBEDO
            }));
            (m.name.clone(), kd, texture)
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
