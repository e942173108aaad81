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
use glam::{Mat3, Mat4, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use std::collections::HashMap;
use std::path::Path;

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
    let mut light: Option<SpotLight> = None;
    let mut camera: Option<(usize, usize, Camera)> = None;
    let mut bound = super::animation::NodeBindings::default();

    // `measure` has bounded the visits and ruled out cycles.
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            bail!("node {} has a non-finite transform", node.index());
        }
        for child in node.children() {
            stack.push((child, world));
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
                    let cam = read_camera(c.index(), node.index(), &p, world)?;
                    // "The first perspective camera": lowest camera index.
                    if camera.as_ref().is_none_or(|(i, _, _)| c.index() < *i) {
                        camera = Some((c.index(), node.index(), cam));
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
    let (lo, hi) = out
        .bounds()
        .ok_or_else(|| anyhow!("the scene has no vertices to render"))?;
    let reach = lo.abs().max(hi.abs()).max_element();
    if reach.is_nan() || reach > limits.coordinate {
        bail!(
            "the scene is too large: its geometry reaches {reach:.3e} m from the origin; isr renders in 32-bit floats and supports coordinates up to {:.0e} m (scale the scene down)",
            limits.coordinate
        );
    }
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
        Some((index, node, c)) => {
            check_znear(index, node, &c, lo, hi)?;
            out.camera = c;
        }
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

/// The document and the GLB binary chunk. A file that starts with the GLB
/// magic, or is named `.glb` and is not JSON, is held to the GLB header.
fn parse(path: &Path, bytes: &[u8]) -> Result<(gltf::Document, Option<Vec<u8>>)> {
    let named_glb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let looks_json = text.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{');
    let bytes = if bytes.starts_with(b"glTF") {
        glb_body(bytes)?
    } else if named_glb && !looks_json {
        bail!("not a valid GLB file: it does not start with the GLB magic \"glTF\"");
    } else if !looks_json {
        bail!("not a valid glTF 2.0 file: it is neither JSON (which starts with '{{') nor GLB (which starts with \"glTF\")");
    } else {
        bytes
    };
    let invalid = |e| match e {
        gltf::Error::Binary(e) => anyhow!("not a valid GLB file: {e}"),
        e => anyhow!("not a valid glTF 2.0 file: {e}"),
    };
    // Validation after `check_json`: gltf-json's own validation indexes the
    // POSITION accessor before checking that it exists (a panic).
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(invalid)?;
    let gltf::Gltf { document, blob } = gltf;
    let root = document.into_json();
    check_json(&root)?;
    // Animation data the validation rejects gets a message naming the
    // animation and channel.
    let document = gltf::Document::from_json(root)
        .map_err(|e| super::animation::explain_invalid(bytes).unwrap_or_else(|| invalid(e)))?;
    Ok((document, blob))
}

/// The GLB header (magic, version 2, total length within the file): the gltf
/// crate checks only the magic. Returns the bytes the header covers.
fn glb_body(bytes: &[u8]) -> Result<&[u8]> {
    let word = |i: usize| {
        bytes
            .get(i..i + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        bail!(
            "not a valid GLB file: {} bytes is shorter than the 12-byte GLB header",
            bytes.len()
        );
    };
    if version != 2 {
        bail!("not a valid GLB file: GLB version {version} is not supported (only 2)");
    }
    let length = length as usize;
    if length > bytes.len() {
        bail!(
            "not a valid GLB file: the header declares {length} bytes but the file has {} (truncated?)",
            bytes.len()
        );
    }
    if length < 20 {
        bail!(
            "not a valid GLB file: the header's length {length} leaves no room for the JSON chunk"
        );
    }
    Ok(&bytes[..length])
}

/// What `gltf`'s validation would panic on, or leaves to accessors that
/// would panic on it.
fn check_json(root: &gltf::json::Root) -> Result<()> {
    use gltf::json::validation::Checked;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                if index.value() >= root.accessors.len() {
                    let name = match semantic {
                        Checked::Valid(s) => s.to_string(),
                        Checked::Invalid => "an attribute".into(),
                    };
                    bail!(
                        "mesh {m} primitive {p}: {name} names accessor {}, which does not exist",
                        index.value()
                    );
                }
            }
        }
    }
    for (i, c) in root.cameras.iter().enumerate() {
        let ok = match c.type_ {
            Checked::Valid(gltf::json::camera::Type::Perspective) => c.perspective.is_some(),
            Checked::Valid(gltf::json::camera::Type::Orthographic) => c.orthographic.is_some(),
            Checked::Invalid => false,
        };
        if !ok {
            bail!("camera {i}: its type has no matching perspective/orthographic object");
        }
    }
    let lights = root
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .map_or(&[][..], |l| &l.lights[..]);
    for (i, l) in lights.iter().enumerate() {
        use gltf::json::extensions::scene::khr_lights_punctual::Type;
        if matches!(l.type_, Checked::Valid(Type::Spot)) && l.spot.is_none() {
            bail!("light {i}: a spot light without its \"spot\" object");
        }
        if matches!(l.type_, Checked::Invalid) {
            bail!("light {i}: unknown light type");
        }
    }
    for (i, n) in root.nodes.iter().enumerate() {
        if let Some(l) = n
            .extensions
            .as_ref()
            .and_then(|e| e.khr_lights_punctual.as_ref())
        {
            if l.light.value() >= lights.len() {
                bail!(
                    "node {i} names light {}, which does not exist",
                    l.light.value()
                );
            }
        }
    }
    for (i, img) in root.images.iter().enumerate() {
        if img.buffer_view.is_some() && img.mime_type.is_none() {
            bail!("image {i}: an image in a buffer view needs a mimeType");
        }
        if img.buffer_view.is_none() && img.uri.is_none() {
            bail!("image {i}: neither a uri nor a bufferView");
        }
    }
    Ok(())
}

/// What instancing the scene will produce, counted on the node graph before
/// any of it is done (saturating: a 40-level DAG counts 2^41 visits without
/// visiting them).
struct Plan {
    visits: u64,
    triangles: u64,
    vertices: u64,
    depth: u64,
}

impl Plan {
    fn check(&self, limits: &Limits) -> Result<()> {
        if self.depth > limits.hierarchy_depth {
            bail!(
                "the node hierarchy is {} levels deep; the limit is {}",
                self.depth,
                limits.hierarchy_depth
            );
        }
        if self.visits > limits.node_visits {
            bail!(
                "the node hierarchy expands to {} node instances (nodes listed under several parents are instanced once per path); the limit is {}",
                count(self.visits),
                limits.node_visits
            );
        }
        if self.triangles > limits.triangles {
            bail!(
                "the scene instances {} triangles; the limit is {}",
                count(self.triangles),
                limits.triangles
            );
        }
        if self.vertices > limits.vertices {
            bail!(
                "the scene instances {} vertices; the limit is {}",
                count(self.vertices),
                limits.vertices
            );
        }
        Ok(())
    }
}

fn count(n: u64) -> String {
    if n == u64::MAX {
        "more than 2^64".into()
    } else {
        n.to_string()
    }
}

/// Per node: visits, triangles, vertices and depth of the subtree under it,
/// memoised over the graph (iterative: no recursion on hostile depth).
fn measure(doc: &gltf::Document, scene: &gltf::Scene) -> Result<Plan> {
    // Triangles and vertices each mesh adds per instance, from accessor counts.
    let mesh_cost: Vec<(u64, u64)> = doc
        .meshes()
        .map(|m| {
            m.primitives()
                .filter(|p| p.mode() == gltf::mesh::Mode::Triangles)
                .fold((0u64, 0u64), |(t, v), p| {
                    let verts = p
                        .get(&gltf::Semantic::Positions)
                        .map_or(0, |a| a.count() as u64);
                    let ids = p.indices().map_or(verts, |a| a.count() as u64);
                    (t.saturating_add(ids / 3), v.saturating_add(verts))
                })
        })
        .collect();
    let n = doc.nodes().len();
    // None: not seen; Some(None): on the current path; Some(Some(plan)): done.
    let mut memo: Vec<Option<Option<Plan>>> = (0..n).map(|_| None).collect();
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut total = Plan {
        visits: 0,
        triangles: 0,
        vertices: 0,
        depth: 0,
    };
    for root in scene.nodes() {
        let mut stack = vec![(root.index(), false)];
        while let Some((i, children_done)) = stack.pop() {
            if children_done {
                let node = &nodes[i];
                let (t, v) = node.mesh().map_or((0, 0), |m| mesh_cost[m.index()]);
                let mut p = Plan {
                    visits: 1,
                    triangles: t,
                    vertices: v,
                    depth: 1,
                };
                for c in node.children() {
                    if let Some(Some(cp)) = &memo[c.index()] {
                        p.visits = p.visits.saturating_add(cp.visits);
                        p.triangles = p.triangles.saturating_add(cp.triangles);
                        p.vertices = p.vertices.saturating_add(cp.vertices);
                        p.depth = p.depth.max(cp.depth.saturating_add(1));
                    }
                }
                memo[i] = Some(Some(p));
                continue;
            }
            match &memo[i] {
                Some(Some(_)) => continue,
                Some(None) => bail!("the node hierarchy has a cycle through node {i}"),
                None => {}
            }
            memo[i] = Some(None);
            stack.push((i, true));
            for c in nodes[i].children() {
                match &memo[c.index()] {
                    Some(None) => bail!(
                        "the node hierarchy has a cycle: node {} is its own ancestor",
                        c.index()
                    ),
                    Some(Some(_)) => {}
                    None => stack.push((c.index(), false)),
                }
            }
        }
        if let Some(Some(p)) = &memo[root.index()] {
            total.visits = total.visits.saturating_add(p.visits);
            total.triangles = total.triangles.saturating_add(p.triangles);
            total.vertices = total.vertices.saturating_add(p.vertices);
            total.depth = total.depth.max(p.depth);
        }
    }
    Ok(total)
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
    // The size from the header, checked before anything is decoded.
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(&bytes))
            .with_guessed_format()
            .map_err(|e| anyhow!("{label}: cannot read ({e})"))
    };
    let (w, h) = reader()?
        .into_dimensions()
        .map_err(|e| anyhow!("{label}: cannot decode ({e}); PNG and JPEG are supported"))?;
    let max = limits.texture_dimension;
    if w > max || h > max {
        bail!("{label} is {w}x{h} pixels; textures may be at most {max}x{max}");
    }
    let pixels = w as u64 * h as u64;
    let total = loader.pixels.saturating_add(pixels);
    if total > limits.texture_pixels {
        bail!(
            "{label} is {w}x{h} = {pixels} pixels, which brings the textures to {total} pixels; the limit is {} pixels for all textures together",
            limits.texture_pixels
        );
    }
    loader.pixels = total;
    let mut reader = reader()?;
    // The decoder itself held to the same size, should the header lie.
    let mut decode_limits = image::Limits::default();
    decode_limits.max_image_width = Some(w);
    decode_limits.max_image_height = Some(h);
    decode_limits.max_alloc = Some(pixels.saturating_mul(8).saturating_add(1 << 20));
    reader.limits(decode_limits);
    let decoded = reader
        .decode()
        .map_err(|e| anyhow!("{label}: cannot decode ({e}); PNG and JPEG are supported"))?
        .to_rgba8();
    Ok(Texture {
        name: label,
        width: decoded.width(),
        height: decoded.height(),
        rgba8: decoded.into_raw(),
    })
}

/// A perspective camera, refused when it cannot give an image: a singular
/// node transform (scale 0), a yfov outside (0, pi) or so close to an end
/// that its tangent is 0 or infinite, a znear that is not a positive normal
/// float. `check_znear` relates znear to the scene once bounds are known.
fn read_camera(
    index: usize,
    node: usize,
    p: &gltf::camera::Perspective,
    world: Mat4,
) -> Result<Camera> {
    let (yfov, znear) = (p.yfov(), p.znear());
    let f = 1.0 / (0.5 * yfov).tan();
    if !(yfov > 0.0 && yfov < std::f32::consts::PI && f.is_finite() && f > 1e-6) {
        bail!("camera {index}: yfov {yfov} must be within (0, pi) radians");
    }
    if !(znear.is_normal() && znear > 0.0) {
        bail!("camera {index}: znear {znear} must be a positive, finite, normal number");
    }
    if !nonsingular(world) {
        bail!(
            "camera {index}: the transform of its node {node} is singular (a scale of 0?), so it has no view direction"
        );
    }
    Ok(Camera {
        world_from_camera: world,
        yfov,
        znear,
    })
}

/// The linear part maps no direction to (nearly) zero.
fn nonsingular(m: Mat4) -> bool {
    let l = Mat3::from_mat4(m);
    let lengths = l.x_axis.length() * l.y_axis.length() * l.z_axis.length();
    let det = l.determinant();
    lengths.is_finite() && lengths > 0.0 && det.is_finite() && det.abs() > 1e-6 * lengths
}

/// Reversed-Z with an infinite far plane stores znear / distance: it must not
/// underflow for the farthest point of the scene.
fn check_znear(index: usize, node: usize, c: &Camera, lo: Vec3, hi: Vec3) -> Result<()> {
    let eye = c.position();
    let far = (lo - eye).abs().max((hi - eye).abs()).length();
    if far.is_finite() && (c.znear as f64) < far as f64 * 1e-30 {
        bail!(
            "camera {index} (node {node}): znear {} is too small for a scene reaching {far:.3e} m from it: depths would underflow to zero (use znear >= {:.1e})",
            c.znear,
            far as f64 * 1e-30
        );
    }
    Ok(())
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
            "light {}: intensity {} must be finite and non-negative",
            l.index(),
            l.intensity()
        );
    }
    let color = Vec3::from(l.color());
    if !(color.is_finite() && color.min_element() >= 0.0 && (color * l.intensity()).is_finite()) {
        bail!(
            "light {}: color {:?} must be finite and non-negative",
            l.index(),
            l.color()
        );
    }
    if let Some(r) = l.range() {
        if !(r.is_finite() && r > 0.0) {
            bail!("light {}: range {r} must be finite and positive", l.index());
        }
    }
    let direction = world.transform_vector3(-Vec3::Z);
    if !direction.is_finite() || direction.length_squared() == 0.0 || !nonsingular(world) {
        bail!(
            "light {}: its node transform is degenerate (a scale of 0?)",
            l.index()
        );
    }
    Ok(SpotLight {
        position: world.transform_point3(Vec3::ZERO),
        direction: direction.normalize(),
        color,
        intensity: l.intensity(),
        inner_cone: inner,
        outer_cone: outer,
        range: l.range(),
    })
}

fn default_light() -> SpotLight {
    fitted_light(Vec3::splat(-1.0), Vec3::splat(1.0))
}

fn default_camera() -> Camera {
    fitted_camera(Vec3::splat(-1.0), Vec3::splat(1.0))
}

/// A spot light just below the top of the bounds, pointing down, bright enough
/// that a white floor at the bottom reflects radiance of about 1 (docs/algorithm.md section 2).
/// Finite for any finite bounds: sizes are taken in f64 and the intensity is
/// clamped to the largest f32 (only reached far beyond `Limits::coordinate`).
pub fn fitted_light(lo: Vec3, hi: Vec3) -> SpotLight {
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let size = (hi - lo).max_element().max(1e-3);
    let center = (lo + hi) * 0.5;
    let position = glam::DVec3::new(center.x, hi.y - 0.05 * size, center.z);
    let drop = (position.y - lo.y).max(0.1 * size);
    SpotLight {
        position: position.as_vec3(),
        direction: -Vec3::Y,
        color: Vec3::ONE,
        intensity: (std::f64::consts::PI * drop * drop).min(f32::MAX as f64) as f32,
        inner_cone: 45f32.to_radians(),
        outer_cone: 60f32.to_radians(),
        range: None,
    }
}

/// A camera on +Z of the bounds, framing them with a 45 degree vertical fov.
/// Computed in f64 so that it stays finite for any finite bounds.
pub fn fitted_camera(lo: Vec3, hi: Vec3) -> Camera {
    // Bounds beyond f32::MAX / 8 (refused by the loader long before, see
    // `Limits::coordinate`) are clamped so the eye stays a finite f32.
    let m = f32::MAX as f64 / 8.0;
    let clamp = |v: Vec3| {
        v.as_dvec3()
            .clamp(glam::DVec3::splat(-m), glam::DVec3::splat(m))
    };
    let (lo, hi) = (clamp(lo), clamp(hi));
    let center = (lo + hi) * 0.5;
    // At least a millionth of the distance from the origin, so that the eye
    // is a different f32 from the centre even for a point far out.
    let radius = ((hi - lo).length() * 0.5)
        .max(1e-3)
        .max(center.abs().max_element() * 1e-6);
    let yfov = 45f64.to_radians();
    let distance = radius / (yfov * 0.5).sin();
    let eye = center + glam::DVec3::Z * distance;
    let view = glam::DMat4::look_at_rh(eye, center, glam::DVec3::Y);
    let znear = (distance - radius).max(distance * 1e-3);
    Camera {
        world_from_camera: view.inverse().as_mat4(),
        yfov: yfov as f32,
        znear: (znear as f32).min(f32::MAX),
    }
}
