//! glTF 2.0 (`.gltf` and `.glb`) to [`Scene`]: triangle meshes through the node
//! hierarchy, `baseColorFactor`/`baseColorTexture` as diffuse albedo, the first
//! `KHR_lights_punctual` spot light and the first perspective camera.
//!
//! Scene files are untrusted input. Buffers and images are resolved here rather
//! than by `gltf::import`, under the URI policy of [`super::uri`] and with
//! bounded reads; accessors are read by [`super::accessor`]; the node graph is
//! measured against [`Limits`] before it is instanced. Every malformed input
//! gets an error that says what is wrong, never a panic (`load_bytes` is
//! fuzzed without a panic guard; `load_with` still catches one, as a backstop).

use super::accessor::{self, format_name};
pub use super::limits::Limits;
use super::{
    compute_normals, uri, Camera, GpuVertex, Instance, Material, Mesh, Scene, SpotLight, Texture,
};
use anyhow::{anyhow, bail, Context as _, Result};
use glam::{DMat4, DVec3, Mat4, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use std::collections::HashMap;
use std::path::Path;

mod camera_light;
use camera_light::*;
pub use camera_light::{fitted_camera, fitted_light};

mod budget;
use budget::*;

mod parse;
use parse::*;

/// Extensions whose absence would change what the file means, that `isr` reads.
const SUPPORTED_REQUIRED: &[&str] = &["KHR_lights_punctual"];

/// How permissive the loader is. The default is the safe one.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Let buffer and image URIs name files outside the scene file's folder:
    /// absolute paths, `..` above it, `file:` URIs and symbolic links out of it
    /// (`--allow-outside-uris`). Only regular files are read even then.
    pub allow_outside_uris: bool,
    /// Budgets checked before the work they bound.
    pub limits: Limits,
}

/// Loads a scene file with the default (safe) options.
pub fn load(path: &Path) -> Result<Scene> {
    load_with(path, &LoadOptions::default())
}

pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scene> {
    std::fs::metadata(path).map_err(|e| {
        anyhow!(
            "cannot read scene file {}: {e}; pass an existing .gltf or .glb file, or omit --scene for the built-in Cornell box",
            path.display()
        )
    })?;
    let bytes = uri::read_capped(path, options.limits.scene_file_bytes, "the scene file")
        .with_context(|| format!("cannot read scene file {}", path.display()))?;
    // A panic here would be a bug (in isr or the gltf crate): `load_bytes` is
    // fuzzed to have none. Should one remain, it becomes an error that names
    // the file rather than a backtrace.
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(|| load_bytes(path, &bytes, options));
    std::panic::set_hook(previous);
    match result {
        Ok(r) => r.with_context(|| format!("loading scene {}", path.display())),
        Err(_) => bail!(
            "loading scene {}: the file is malformed in a way the glTF reader could not handle",
            path.display()
        ),
    }
}

/// Loads a scene from `bytes` as if read from `path`: URIs resolve in `path`'s
/// folder, `.glb` in its name expects a GLB, its stem names the scene. `path`
/// itself is not read. Does not catch panics (there should be none).
pub fn load_bytes(path: &Path, bytes: &[u8], options: &LoadOptions) -> Result<Scene> {
    let limits = &options.limits;
    let (doc, blob) = parse(path, bytes)?;
    let doc = &doc;
    for ext in doc.extensions_required() {
        if !SUPPORTED_REQUIRED.contains(&ext) {
            bail!("the file requires glTF extension {ext}, which isr does not support");
        }
    }
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| anyhow!("the file has no scene"))?;
    // Budgets first: nothing below allocates more than they allow.
    let plan = measure(doc, &scene)?;
    plan.check(limits)?;
    let materials = doc.materials().len() as u64;
    if materials > limits.materials {
        bail!(
            "the file has {materials} materials; the limit is {}",
            limits.materials
        );
    }
    let buffers = load_buffers(doc, &base, blob.as_deref(), options)?;
    let mut warnings = Vec::new();

    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let mut out = Scene::empty(&name, default_light(), default_camera());
    let mut mesh_ids: HashMap<(usize, usize), usize> = HashMap::new();
    let mut material_ids: HashMap<Option<usize>, usize> = HashMap::new();
    let mut textures = TextureLoader {
        ids: HashMap::new(),
        pixels: 0,
        base: &base,
        options,
    };
    let mut lights: Vec<(usize, SpotLight)> = Vec::new();
    let mut camera: Option<(usize, usize, Camera)> = None;
    let mut bound = super::animation::NodeBindings::default();

    // `measure` has bounded the visits and ruled out cycles. Each world
    // transform is composed twice: in f32, as it always was (what a scene
    // near the world's origin keeps, bit for bit), and in f64, which a
    // scene far from it is stored from, relative to its origin (below).
    let mut stack: Vec<(gltf::Node, Mat4, DMat4)> = scene
        .nodes()
        .map(|n| (n, Mat4::IDENTITY, DMat4::IDENTITY))
        .collect();
    let mut worlds: Vec<DMat4> = Vec::new();
    let mut light_nodes: Vec<(gltf::khr_lights_punctual::Light, usize, Mat4, DMat4)> = Vec::new();
    let mut camera_nodes = Vec::new();
    while let Some((node, parent, parent64)) = stack.pop() {
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        let world64 = parent64 * local.as_dmat4();
        if !world.is_finite() {
            bail!("node {} has a non-finite transform", node.index());
        }
        for child in node.children() {
            stack.push((child, world, world64));
        }
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let key = (mesh.index(), prim.index());
                let id = match mesh_ids.get(&key) {
                    Some(&id) => Some(id),
                    None => {
                        let mat_key = prim.material().index();
                        let material = match material_ids.get(&mat_key) {
                            Some(&m) => m,
                            None => {
                                let m = load_material(
                                    &prim.material(),
                                    &buffers,
                                    &mut out,
                                    &mut textures,
                                    &mut warnings,
                                )?;
                                material_ids.insert(mat_key, m);
                                m
                            }
                        };
                        let loaded = load_primitive(
                            &mesh,
                            &prim,
                            &buffers,
                            material,
                            limits,
                            &mut warnings,
                        )?;
                        loaded.map(|m| {
                            out.meshes.push(m);
                            mesh_ids.insert(key, out.meshes.len() - 1);
                            out.meshes.len() - 1
                        })
                    }
                };
                if let Some(id) = id {
                    out.instances.push(Instance {
                        mesh: id,
                        world_from_object: world,
                    });
                    worlds.push(world64);
                    bound.instances.push(node.index());
                }
            }
        }
        if let Some(l) = node.light() {
            light_nodes.push((l, node.index(), world, world64));
        }
        if let Some(c) = node.camera() {
            camera_nodes.push((c, node.index(), world, world64));
        }
    }
    if out.instances.is_empty() {
        bail!("the scene has no triangle geometry to render");
    }
    // Far from the world's origin for its size, the scene is stored relative
    // to an origin of its own, from the f64 transforms.
    out.origin = origin_of(&out, &worlds);
    let origin = out.origin;
    let place = |world: Mat4, world64: DMat4| {
        if origin == DVec3::ZERO {
            world
        } else {
            (DMat4::from_translation(-origin) * world64).as_mat4()
        }
    };
    for (inst, world64) in out.instances.iter_mut().zip(&worlds) {
        inst.world_from_object = place(inst.world_from_object, *world64);
    }
    for (l, node, world, world64) in light_nodes {
        // Every light node is a light (a light instanced by two nodes
        // shines from both); ordered by node below, so the order is the
        // file's and not the traversal's.
        lights.push((node, read_light(&l, place(world, world64))?));
    }
    for (c, node, world, world64) in camera_nodes {
        match c.projection() {
            gltf::camera::Projection::Perspective(p) => {
                let cam = read_camera(c.index(), node, &p, place(world, world64))?;
                // "The first perspective camera": lowest camera index.
                if camera.as_ref().is_none_or(|(i, _, _)| c.index() < *i) {
                    camera = Some((c.index(), node, cam));
                    bound.camera = Some(node);
                }
            }
            gltf::camera::Projection::Orthographic(_) => warnings.push(format!(
                "camera {} skipped: orthographic cameras are not supported",
                c.index()
            )),
        }
    }
    let (lo, hi) = limits.check_extent(&out, "scale the scene down")?;
    lights.sort_by_key(|&(node, _)| node);
    if lights.is_empty() {
        let l = fitted_light(lo, hi);
        warnings.push(format!(
            "no KHR_lights_punctual light: using a default spot light at {:.2?} pointing down (60 degree cone, {:.1} cd)",
            (origin + l.position.as_dvec3()).to_array(),
            l.intensity
        ));
        (out.lights, out.bare.light) = (vec![l], true);
    } else {
        bound.lights = lights.iter().map(|&(node, _)| node).collect();
        out.lights = lights.into_iter().map(|(_, l)| l).collect();
    }
    match camera {
        Some((index, node, c)) => {
            check_znear(index, node, &c, lo, hi)?;
            out.camera = c;
        }
        None => {
            (out.camera, out.bare.camera) = (fitted_camera(lo, hi), true);
            warnings.push(
                "no perspective camera: using a default camera on +Z looking at the scene's center"
                    .into(),
            );
        }
    }
    out.animation = super::animation::from_gltf(doc, &buffers, &bound, origin, &mut warnings)?;
    out.warnings = warnings;
    Ok(out)
}

/// The scene's origin (`scene_origin`) from its world bounds in f64: each
/// instance's vertices through its f64 world transform `worlds[i]`.
fn origin_of(scene: &Scene, worlds: &[DMat4]) -> DVec3 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for (inst, world) in scene.instances.iter().zip(worlds) {
        for v in &scene.meshes[inst.mesh].vertices {
            let p = world.transform_point3(Vec3::from(v.position).as_dvec3());
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    crate::scene::scene_origin(lo, hi)
}

fn load_buffers(
    doc: &gltf::Document,
    base: &Path,
    blob: Option<&[u8]>,
    options: &LoadOptions,
) -> Result<Vec<Vec<u8>>> {
    let declared = doc
        .buffers()
        .fold(0u64, |s, b| s.saturating_add(b.length() as u64));
    if declared > options.limits.buffer_bytes {
        bail!(
            "the buffers declare {} in all; the limit is {}",
            super::limits::bytes(declared),
            super::limits::bytes(options.limits.buffer_bytes)
        );
    }
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let (i, len) = (buffer.index(), buffer.length());
        let mut data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    anyhow!("buffer {i} refers to the GLB binary chunk, but there is none")
                })?
                .get(..len)
                .ok_or_else(|| {
                    anyhow!(
                        "buffer {i} has {} bytes but the file declares byteLength {len}: the buffer is truncated",
                        blob.map_or(0, <[u8]>::len)
                    )
                })?
                .to_vec(),
            gltf::buffer::Source::Uri(u) => {
                let what = || format!("reading buffer {i} ({})", short(u));
                match uri::resolve(u, base, options.allow_outside_uris).with_context(what)? {
                    uri::Source::Data(d) => d,
                    uri::Source::File(p) => {
                        uri::read_prefix(&p, len as u64, &format!("buffer {i}")).with_context(what)?
                    }
                }
            }
        };
        if data.len() < len {
            bail!(
                "buffer {i} has {} bytes but the file declares byteLength {len}: the buffer is truncated",
                data.len()
            );
        }
        // Views must lie within the declared length, not whatever follows.
        data.truncate(len);
        out.push(data);
    }
    Ok(out)
}

fn short(uri: &str) -> String {
    if uri.len() > 60 {
        format!(
            "{}...",
            &uri[..uri.char_indices().nth(57).map_or(uri.len(), |(i, _)| i)]
        )
    } else {
        uri.to_string()
    }
}

fn load_primitive(
    mesh: &gltf::Mesh,
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    material: usize,
    limits: &Limits,
    warnings: &mut Vec<String>,
) -> Result<Option<Mesh>> {
    let label = format!(
        "mesh {} ({}) primitive {}",
        mesh.index(),
        mesh.name().unwrap_or("unnamed"),
        prim.index()
    );
    if prim.mode() != gltf::mesh::Mode::Triangles {
        warnings.push(format!(
            "{label} skipped: mode {:?} is not triangles",
            prim.mode()
        ));
        return Ok(None);
    }
    let Some(pos_acc) = prim.get(&gltf::Semantic::Positions) else {
        warnings.push(format!("{label} skipped: it has no POSITION attribute"));
        return Ok(None);
    };
    // The spec's types (KHR_mesh_quantization, which allows others, is not
    // supported and so refused as a required extension).
    let is = |a: &gltf::Accessor, t: DataType, d: Dimensions| {
        a.data_type() == t && a.dimensions() == d && !a.normalized()
    };
    if !is(&pos_acc, DataType::F32, Dimensions::Vec3) {
        bail!(
            "{label}: POSITION must be FLOAT VEC3 (the glTF spec), not {}",
            format_name(&pos_acc)
        );
    }
    let positions: Vec<[f32; 3]> =
        accessor::read_f32(&format!("{label}: POSITION"), &pos_acc, buffers)?;
    if let Some(i) = positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        bail!(
            "{label}: vertex {i} has a non-finite position {:?}",
            positions[i]
        );
    }
    let n = positions.len();
    let indices: Vec<u32> = match prim.indices() {
        Some(acc) => {
            if !matches!(
                acc.data_type(),
                DataType::U8 | DataType::U16 | DataType::U32
            ) || acc.dimensions() != Dimensions::Scalar
            {
                bail!(
                    "{label}: indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT SCALAR (the glTF spec), not {}",
                    format_name(&acc)
                );
            }
            accessor::read_u32(&format!("{label}: indices"), &acc, buffers)?
        }
        None => (0..n as u32).collect(),
    };
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= n) {
        bail!("{label}: index {bad} is out of range for {n} vertices");
    }
    if !indices.len().is_multiple_of(3) {
        bail!("{label}: {} indices is not a multiple of 3", indices.len());
    }
    let mut vertices: Vec<GpuVertex> = positions
        .iter()
        .map(|p| GpuVertex {
            position: *p,
            ..Default::default()
        })
        .collect();
    match prim.get(&gltf::Semantic::Normals) {
        Some(acc) => {
            if !is(&acc, DataType::F32, Dimensions::Vec3) {
                bail!(
                    "{label}: NORMAL must be FLOAT VEC3 (the glTF spec), not {}",
                    format_name(&acc)
                );
            }
            if acc.count() != n {
                bail!(
                    "{label}: NORMAL has {} entries for {n} positions",
                    acc.count()
                );
            }
            let normals: Vec<[f32; 3]> =
                accessor::read_f32(&format!("{label}: NORMAL"), &acc, buffers)?;
            for (i, (v, nrm)) in vertices.iter_mut().zip(normals).enumerate() {
                let nv = Vec3::from(nrm);
                if !nv.is_finite() {
                    bail!("{label}: vertex {i} has a non-finite normal {nrm:?}");
                }
                // Unit length is required; scale it rather than refuse, and
                // give a zero normal (degenerate, common in exports) +Y.
                v.normal = nv.normalize_or(Vec3::Y).to_array();
            }
        }
        None => compute_normals(&mut vertices, &indices),
    }
    if let Some(acc) = prim.get(&gltf::Semantic::TexCoords(0)) {
        let ok = acc.dimensions() == Dimensions::Vec2
            && match acc.data_type() {
                DataType::F32 => !acc.normalized(),
                DataType::U8 | DataType::U16 => acc.normalized(),
                _ => false,
            };
        if !ok {
            bail!(
                "{label}: TEXCOORD_0 must be FLOAT, normalized UNSIGNED_BYTE or normalized UNSIGNED_SHORT VEC2 (the glTF spec), not {}",
                format_name(&acc)
            );
        }
        if acc.count() != n {
            bail!(
                "{label}: TEXCOORD_0 has {} entries for {n} positions",
                acc.count()
            );
        }
        let uvs: Vec<[f32; 2]> =
            accessor::read_f32(&format!("{label}: TEXCOORD_0"), &acc, buffers)?;
        for (i, (v, uv)) in vertices.iter_mut().zip(uvs).enumerate() {
            if !uv.iter().all(|c| c.is_finite()) {
                bail!("{label}: vertex {i} has a non-finite TEXCOORD_0 {uv:?}");
            }
            if uv.iter().any(|c| c.abs() > limits.texcoord) {
                bail!(
                    "{label}: vertex {i} has the TEXCOORD_0 {uv:?}; isr supports texture coordinates up to {} (repeats of the texture): beyond, 32-bit floats keep too few bits for a texel",
                    limits.texcoord
                );
            }
            v.uv = uv;
        }
    }
    if mesh.weights().is_some() || prim.morph_targets().next().is_some() {
        warnings.push(format!("{label}: morph targets ignored"));
    }
    Ok(Some(Mesh {
        name: format!("{}#{}", mesh.name().unwrap_or("mesh"), prim.index()),
        vertices,
        indices,
        material,
    }))
}

/// Images, decoded once each, with the pixel budget counted from their headers.
struct TextureLoader<'a> {
    ids: HashMap<usize, usize>,
    pixels: u64,
    base: &'a Path,
    options: &'a LoadOptions,
}

fn load_material(
    m: &gltf::Material,
    buffers: &[Vec<u8>],
    scene: &mut Scene,
    textures: &mut TextureLoader,
    warnings: &mut Vec<String>,
) -> Result<usize> {
    let pbr = m.pbr_metallic_roughness();
    let name = m.name().unwrap_or("material").to_string();
    if m.alpha_mode() != gltf::material::AlphaMode::Opaque {
        warnings.push(format!(
            "material {name}: alphaMode {:?} treated as OPAQUE",
            m.alpha_mode()
        ));
    }
    let base_color = Vec4::from(pbr.base_color_factor());
    if !base_color.is_finite() {
        bail!("material {name}: non-finite baseColorFactor");
    }
    let texture = match pbr.base_color_texture() {
        None => None,
        Some(info) => {
            if info.tex_coord() != 0 {
                warnings.push(format!(
                    "material {name}: texCoord {} read as TEXCOORD_0",
                    info.tex_coord()
                ));
            }
            let image = info.texture().source();
            Some(match textures.ids.get(&image.index()) {
                Some(&t) => t,
                None => {
                    let t = load_image(&image, buffers, textures)?;
                    scene.textures.push(t);
                    textures.ids.insert(image.index(), scene.textures.len() - 1);
                    scene.textures.len() - 1
                }
            })
        }
    };
    scene.materials.push(Material {
        name,
        base_color,
        texture,
        double_sided: m.double_sided(),
    });
    Ok(scene.materials.len() - 1)
}

fn load_image(
    image: &gltf::Image,
    buffers: &[Vec<u8>],
    loader: &mut TextureLoader,
) -> Result<Texture> {
    let limits = &loader.options.limits;
    let label = format!(
        "image {} ({})",
        image.index(),
        image.name().unwrap_or("unnamed")
    );
    let bytes = match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buf = buffers
                .get(view.buffer().index())
                .ok_or_else(|| anyhow!("{label}: its buffer view names a missing buffer"))?;
            view.offset()
                .checked_add(view.length())
                .and_then(|end| buf.get(view.offset()..end))
                .ok_or_else(|| anyhow!("{label}: buffer view lies outside its buffer"))?
                .to_vec()
        }
        gltf::image::Source::Uri { uri: u, .. } => {
            let what = || format!("reading {label} from {}", short(u));
            match uri::resolve(u, loader.base, loader.options.allow_outside_uris)
                .with_context(what)?
            {
                uri::Source::Data(d) => d,
                uri::Source::File(p) => {
                    uri::read_capped(&p, limits.image_file_bytes, "the image file")
                        .with_context(what)?
                }
            }
        }
    };
    if bytes.len() as u64 > limits.image_file_bytes {
        bail!(
            "{label} is {}, more than the limit of {}",
            super::limits::bytes(bytes.len() as u64),
            super::limits::bytes(limits.image_file_bytes)
        );
    }
    super::texture_decode::decode_texture(&bytes, label, limits, &mut loader.pixels)
}
