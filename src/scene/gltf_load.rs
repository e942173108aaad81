//! glTF 2.0 (`.gltf` and `.glb`) to [`Scene`]: triangle meshes through the node
//! hierarchy, `baseColorFactor`/`baseColorTexture` as diffuse albedo, the first
//! `KHR_lights_punctual` spot light and the first perspective camera.
//!
//! Buffers and images are resolved here rather than by `gltf::import`, so that a
//! missing or short buffer is reported by name instead of as a generic I/O error.

use super::{
    compute_normals, Camera, GpuVertex, Instance, Material, Mesh, Scene, SpotLight, Texture,
};
use anyhow::{anyhow, bail, Context as _, Result};
use base64::Engine as _;
use glam::{Mat4, Vec3, Vec4};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Extensions whose absence would change what the file means, that `isr` reads.
const SUPPORTED_REQUIRED: &[&str] = &["KHR_lights_punctual"];

pub fn load(path: &Path) -> Result<Scene> {
    let bytes = std::fs::read(path).map_err(|e| {
        anyhow!(
            "cannot read scene file {}: {e}; pass an existing .gltf or .glb file, or omit --scene for the built-in Cornell box",
            path.display()
        )
    })?;
    // The gltf crate indexes slices it has validated; a panic would still be a bug
    // in it, so turn one into an error that names the file rather than a backtrace.
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(|| load_bytes(path, &bytes));
    std::panic::set_hook(previous);
    match result {
        Ok(r) => r.with_context(|| format!("loading scene {}", path.display())),
        Err(_) => bail!(
            "loading scene {}: the file is malformed in a way the glTF reader could not handle",
            path.display()
        ),
    }
}

fn load_bytes(path: &Path, bytes: &[u8]) -> Result<Scene> {
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| {
        super::animation::explain_invalid(bytes)
            .unwrap_or_else(|| anyhow!("not a valid glTF 2.0 file: {e}"))
    })?;
    let doc = &gltf.document;
    for ext in doc.extensions_required() {
        if !SUPPORTED_REQUIRED.contains(&ext) {
            bail!("the file requires glTF extension {ext}, which isr does not support");
        }
    }
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let buffers = load_buffers(doc, &base, gltf.blob.as_deref())?;
    let mut warnings = Vec::new();

    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| anyhow!("the file has no scene"))?;

    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let mut out = Scene::empty(&name, default_light(), default_camera());
    let mut mesh_ids: HashMap<(usize, usize), usize> = HashMap::new();
    let mut material_ids: HashMap<Option<usize>, usize> = HashMap::new();
    let mut texture_ids: HashMap<usize, usize> = HashMap::new();
    let mut light: Option<SpotLight> = None;
    let mut camera: Option<(usize, Camera)> = None;
    let mut bound = super::animation::NodeBindings::default();

    let mut stack: Vec<(gltf::Node, Mat4, usize)> =
        scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > 256 {
            bail!("the node hierarchy is deeper than 256 levels (a cycle?)");
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            bail!("node {} has a non-finite transform", node.index());
        }
        for child in node.children() {
            stack.push((child, world, depth + 1));
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
                                    &base,
                                    &mut out,
                                    &mut texture_ids,
                                    &mut warnings,
                                )?;
                                material_ids.insert(mat_key, m);
                                m
                            }
                        };
                        let loaded =
                            load_primitive(&mesh, &prim, &buffers, material, &mut warnings)?;
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
                    bound.instances.push(node.index());
                }
            }
        }
        if let Some(l) = node.light() {
            let spot = read_light(&l, world)?;
            if light.is_none() {
                light = Some(spot);
                bound.light = Some(node.index());
            } else {
                warnings.push(format!(
                    "light {} ignored: isr renders one light per frame (the first spot light is used)",
                    l.index()
                ));
            }
        }
        if let Some(c) = node.camera() {
            match c.projection() {
                gltf::camera::Projection::Perspective(p) => {
                    let cam = Camera {
                        world_from_camera: world,
                        yfov: p.yfov(),
                        znear: p.znear(),
                    };
                    if !(cam.yfov > 0.0 && cam.yfov < std::f32::consts::PI && cam.znear > 0.0) {
                        bail!("camera {} has an invalid yfov or znear", c.index());
                    }
                    // "The first perspective camera": lowest camera index.
                    if camera.as_ref().is_none_or(|(i, _)| c.index() < *i) {
                        camera = Some((c.index(), cam));
                        bound.camera = Some(node.index());
                    }
                }
                gltf::camera::Projection::Orthographic(_) => warnings.push(format!(
                    "camera {} skipped: orthographic cameras are not supported",
                    c.index()
                )),
            }
        }
    }
    if out.instances.is_empty() {
        bail!("the scene has no triangle geometry to render");
    }
    let (lo, hi) = out.bounds().expect("instances exist");
    match light {
        Some(l) => out.light = l,
        None => {
            out.light = fitted_light(lo, hi);
            warnings.push(format!(
                "no KHR_lights_punctual spot light: using a default spot light at {:.2?} pointing down (60 degree cone, {:.1} cd)",
                out.light.position.to_array(),
                out.light.intensity
            ));
        }
    }
    match camera {
        Some((_, c)) => out.camera = c,
        None => {
            out.camera = fitted_camera(lo, hi);
            warnings.push(
                "no perspective camera: using a default camera on +Z looking at the scene's center"
                    .into(),
            );
        }
    }
    out.animation = super::animation::from_gltf(doc, &buffers, &bound, &mut warnings)?;
    out.warnings = warnings;
    Ok(out)
}

fn load_buffers(doc: &gltf::Document, base: &Path, blob: Option<&[u8]>) -> Result<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    anyhow!(
                        "buffer {} refers to the GLB binary chunk, but there is none",
                        buffer.index()
                    )
                })?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => read_uri(uri, base)
                .with_context(|| format!("reading buffer {} ({})", buffer.index(), short(uri)))?,
        };
        if data.len() < buffer.length() {
            bail!(
                "buffer {} has {} bytes but the file declares byteLength {}: the buffer is truncated",
                buffer.index(),
                data.len(),
                buffer.length()
            );
        }
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

/// Bytes of a `data:` URI or of a file relative to the glTF file.
fn read_uri(uri: &str, base: &Path) -> Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest
            .split_once(',')
            .ok_or_else(|| anyhow!("malformed data URI (no comma)"))?;
        if !header.ends_with(";base64") {
            bail!("only base64 data URIs are supported");
        }
        return base64::engine::general_purpose::STANDARD
            .decode(payload.trim())
            .map_err(|e| anyhow!("malformed base64 in data URI: {e}"));
    }
    if uri.contains("://") {
        bail!("external URI {uri}: only files next to the glTF and data URIs are supported");
    }
    let file: PathBuf = base.join(percent_decode(uri));
    std::fs::read(&file).map_err(|e| anyhow!("cannot read {}: {e}", file.display()))
}

fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let Ok(v) = u8::from_str_radix(&s[i + 1..i + 3], 16) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn load_primitive(
    mesh: &gltf::Mesh,
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    material: usize,
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
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let Some(positions) = reader.read_positions() else {
        if prim.get(&gltf::Semantic::Positions).is_some() {
            bail!("{label}: POSITION data lies outside its buffer view or buffer (truncated?)");
        }
        warnings.push(format!("{label} skipped: it has no POSITION attribute"));
        return Ok(None);
    };
    let positions: Vec<[f32; 3]> = positions.collect();
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
    let indices: Vec<u32> = match reader.read_indices() {
        Some(ix) => ix.into_u32().collect(),
        None if prim.indices().is_some() => {
            bail!("{label}: index data lies outside its buffer view or buffer (truncated?)")
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
    match reader.read_normals() {
        Some(normals) => {
            let normals: Vec<[f32; 3]> = normals.collect();
            if normals.len() != n {
                bail!(
                    "{label}: NORMAL has {} entries for {n} positions",
                    normals.len()
                );
            }
            for (v, nrm) in vertices.iter_mut().zip(normals) {
                let nv = Vec3::from(nrm);
                v.normal = if nv.is_finite() && nv.length_squared() > 0.0 {
                    nv.normalize().to_array()
                } else {
                    [0.0, 1.0, 0.0]
                };
            }
        }
        None => compute_normals(&mut vertices, &indices),
    }
    if let Some(uvs) = reader.read_tex_coords(0) {
        for (v, uv) in vertices.iter_mut().zip(uvs.into_f32()) {
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

fn load_material(
    m: &gltf::Material,
    buffers: &[Vec<u8>],
    base: &Path,
    scene: &mut Scene,
    texture_ids: &mut HashMap<usize, usize>,
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
            Some(match texture_ids.get(&image.index()) {
                Some(&t) => t,
                None => {
                    let t = load_image(&image, buffers, base)?;
                    scene.textures.push(t);
                    texture_ids.insert(image.index(), scene.textures.len() - 1);
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

fn load_image(image: &gltf::Image, buffers: &[Vec<u8>], base: &Path) -> Result<Texture> {
    let label = format!(
        "image {} ({})",
        image.index(),
        image.name().unwrap_or("unnamed")
    );
    let bytes = match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buf = &buffers[view.buffer().index()];
            buf.get(view.offset()..view.offset() + view.length())
                .ok_or_else(|| anyhow!("{label}: buffer view lies outside its buffer"))?
                .to_vec()
        }
        gltf::image::Source::Uri { uri, .. } => {
            read_uri(uri, base).with_context(|| format!("reading {label}"))?
        }
    };
    let decoded = image::load_from_memory(&bytes)
        .map_err(|e| anyhow!("{label}: cannot decode ({e}); PNG and JPEG are supported"))?
        .to_rgba8();
    Ok(Texture {
        name: label,
        width: decoded.width(),
        height: decoded.height(),
        rgba8: decoded.into_raw(),
    })
}

fn read_light(l: &gltf::khr_lights_punctual::Light, world: Mat4) -> Result<SpotLight> {
    use gltf::khr_lights_punctual::Kind;
    let (inner, outer) = match l.kind() {
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => (inner_cone_angle, outer_cone_angle),
        Kind::Point => bail!(
            "light {} is a point light: not supported yet (isr renders spot lights; point and directional lights come later)",
            l.index()
        ),
        Kind::Directional => bail!(
            "light {} is a directional light: not supported yet (isr renders spot lights; point and directional lights come later)",
            l.index()
        ),
    };
    let half_pi = std::f32::consts::FRAC_PI_2;
    if !((0.0..half_pi).contains(&inner) && outer > inner && outer <= half_pi) {
        bail!(
            "light {}: cone angles must satisfy 0 <= inner < outer <= pi/2 (got {inner}, {outer})",
            l.index()
        );
    }
    if !(l.intensity().is_finite() && l.intensity() >= 0.0) {
        bail!(
            "light {}: intensity must be finite and non-negative",
            l.index()
        );
    }
    let direction = world.transform_vector3(-Vec3::Z);
    if !direction.is_finite() || direction.length_squared() == 0.0 {
        bail!("light {}: its node transform is degenerate", l.index());
    }
    Ok(SpotLight {
        position: world.transform_point3(Vec3::ZERO),
        direction: direction.normalize(),
        color: Vec3::from(l.color()),
        intensity: l.intensity(),
        inner_cone: inner,
        outer_cone: outer,
        range: l.range().filter(|r| *r > 0.0),
    })
}

fn default_light() -> SpotLight {
    fitted_light(Vec3::splat(-1.0), Vec3::splat(1.0))
}

fn default_camera() -> Camera {
    fitted_camera(Vec3::splat(-1.0), Vec3::splat(1.0))
}

/// A spot light just below the top of the bounds, pointing down, bright enough
/// that a white floor at the bottom reflects radiance of about 1 (ALGORITHM.md 2).
pub fn fitted_light(lo: Vec3, hi: Vec3) -> SpotLight {
    let size = (hi - lo).max_element().max(1e-3);
    let center = (lo + hi) * 0.5;
    let position = Vec3::new(center.x, hi.y - 0.05 * size, center.z);
    let drop = (position.y - lo.y).max(0.1 * size);
    SpotLight {
        position,
        direction: -Vec3::Y,
        color: Vec3::ONE,
        intensity: std::f32::consts::PI * drop * drop,
        inner_cone: 45f32.to_radians(),
        outer_cone: 60f32.to_radians(),
        range: None,
    }
}

/// A camera on +Z of the bounds, framing them with a 45 degree vertical fov.
pub fn fitted_camera(lo: Vec3, hi: Vec3) -> Camera {
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    let yfov = 45f32.to_radians();
    let distance = radius / (yfov * 0.5).sin();
    Camera::look_at(
        center + Vec3::Z * distance,
        center,
        Vec3::Y,
        yfov,
        (distance - radius).max(distance * 1e-3),
    )
}
