//! Animations read from a glTF document, every index, count and value checked
//! so that bad data gets an error naming the animation and channel.

use super::*;

/// Keyframe counts above this are refused, so that a corrupt accessor count
/// cannot exhaust memory (2^20 keys is hours of keys at 60 per second).
pub(super) const MAX_KEYS: usize = 1 << 20;

pub(super) fn label(index: usize, name: Option<&str>, channel: usize) -> String {
    match name {
        Some(n) => format!("animation {index} ({n:?}) channel {channel}"),
        None => format!("animation {index} channel {channel}"),
    }
}

/// The animations of a loaded glTF document, reduced to what moves the
/// instances, camera and light the loader made (`bound`). `None` when nothing
/// moves. Skins and morph-target weights are ignored with a warning.
pub fn from_gltf(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    bound: &NodeBindings,
    origin: glam::DVec3,
    warnings: &mut Vec<String>,
) -> Result<Option<Animation>> {
    let skins = doc.skins().count();
    if skins > 0 {
        warnings.push(format!(
            "{skins} skin(s) ignored: skinned meshes are drawn unskinned at their node"
        ));
    }
    if doc.animations().len() == 0 {
        return Ok(None);
    }
    // The JSON (not the buffers) is copied once to check what the accessors
    // below would unwrap.
    check_references(&doc.clone().into_json())?;
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut channels = Vec::new();
    for anim in doc.animations() {
        for (c, channel) in anim.channels().enumerate() {
            let label = label(anim.index(), anim.name(), c);
            let node = channel.target().node();
            let property = match channel.target().property() {
                gltf::animation::Property::Translation => Property::Translation,
                gltf::animation::Property::Rotation => Property::Rotation,
                gltf::animation::Property::Scale => Property::Scale,
                gltf::animation::Property::MorphTargetWeights => {
                    warnings.push(format!("{label}: morph target weights ignored"));
                    continue;
                }
            };
            if let gltf::scene::Transform::Matrix { .. } = node.transform() {
                bail!(
                    "{label} targets node {}, which has a matrix: glTF animates only nodes given by translation, rotation and scale",
                    node.index()
                );
            }
            let sampler = channel.sampler();
            let interpolation = match sampler.interpolation() {
                gltf::animation::Interpolation::Step => Interpolation::Step,
                gltf::animation::Interpolation::Linear => Interpolation::Linear,
                gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
            };
            let times = read_floats(&sampler.input(), buffers, 1, false)
                .map_err(|e| anyhow!("{label}: input {e}"))?;
            let width = if property == Property::Rotation { 4 } else { 3 };
            let flat = read_floats(
                &sampler.output(),
                buffers,
                width,
                property == Property::Rotation,
            )
            .map_err(|e| anyhow!("{label}: output {e}"))?;
            let values = flat
                .chunks_exact(width)
                .map(|v| Vec4::new(v[0], v[1], v[2], if width == 4 { v[3] } else { 0.0 }))
                .collect();
            channels.push(
                Channel::new(node.index(), property, interpolation, times, values)
                    .map_err(|e| anyhow!("{label}: {e}"))?
                    .labelled(label.clone()),
            );
        }
    }
    if channels.is_empty() {
        return Ok(None);
    }

    let count = nodes.len();
    let mut parent: Vec<Option<usize>> = vec![None; count];
    for n in &nodes {
        for c in n.children() {
            if let Some(p) = parent[c.index()].replace(n.index()) {
                bail!(
                    "node {} is a child of both node {p} and node {}: glTF nodes must form a tree, and animation needs one parent per node",
                    c.index(),
                    n.index()
                );
            }
        }
    }
    let mut animated = vec![false; count];
    for c in &channels {
        animated[c.node] = true;
    }
    // Affected: animated or below an animated node. Parents are resolved
    // first by walking up; a walk longer than the node count is a cycle.
    let mut affected: Vec<Option<bool>> = vec![None; count];
    for n in 0..count {
        let mut chain = vec![];
        let mut m = Some(n);
        let mut above = false;
        while let Some(k) = m {
            if let Some(a) = affected[k] {
                above = a;
                break;
            }
            chain.push(k);
            if chain.len() > count {
                bail!("the node hierarchy has a cycle through node {k}");
            }
            m = parent[k];
        }
        for &k in chain.iter().rev() {
            above |= animated[k];
            affected[k] = Some(above);
        }
    }
    let affected = |k: usize| affected[k] == Some(true);
    let local = |k: usize| Mat4::from_cols_array_2d(&nodes[k].transform().matrix());
    // World transform of a static node, composed root first as the loader
    // does: in f32, or in f64 relative to the scene's origin where it has
    // one (`Scene::origin`).
    let rest_world = |k: usize| {
        let mut chain = vec![k];
        while let Some(p) = parent[chain[chain.len() - 1]] {
            chain.push(p);
        }
        if origin == glam::DVec3::ZERO {
            return chain
                .iter()
                .rev()
                .fold(Mat4::IDENTITY, |w, &n| w * local(n));
        }
        chain
            .iter()
            .rev()
            .fold(glam::DMat4::from_translation(-origin), |w, &n| {
                w * local(n).as_dmat4()
            })
            .as_mat4()
    };
    // Above a root node: the world, relative to the scene's origin.
    let root = glam::DMat4::from_translation(-origin).as_mat4();

    let mut anim = Animation::default();
    let mut slot: Vec<Option<usize>> = vec![None; count];
    // The animation node that carries glTF node `n`, created with its
    // affected ancestors on first use; `None` when nothing above `n` moves.
    let mut slot_of = |n: usize, anim: &mut Animation| -> Result<Option<usize>> {
        let mut chain = vec![];
        let mut m = Some(n);
        let mut above = loop {
            let Some(k) = m else {
                break Parent::Fixed(root);
            };
            if let Some(s) = slot[k] {
                break Parent::Node(s);
            }
            if !affected(k) {
                break Parent::Fixed(rest_world(k));
            }
            chain.push(k);
            m = parent[k];
        };
        for &k in chain.iter().rev() {
            let node_local = if animated[k] {
                let (t, r, s) = nodes[k].transform().decomposed();
                let rotation = Vec4::from(r)
                    .try_normalize()
                    .ok_or_else(|| anyhow!("node {k} has a zero rotation quaternion"))?;
                Local::Animated(Trs {
                    translation: Vec3::from(t),
                    rotation: Quat::from_vec4(rotation),
                    scale: Vec3::from(s),
                })
            } else {
                Local::Fixed(local(k))
            };
            let s = anim
                .add_node(above, node_local)
                .map_err(|e| anyhow!("node {k}: {e}"))?;
            slot[k] = Some(s);
            above = Parent::Node(s);
        }
        Ok(slot[n])
    };
    for (i, &n) in bound.instances.iter().enumerate() {
        if let Some(s) = slot_of(n, &mut anim)? {
            anim.attach_instance(i, s);
        }
    }
    if let Some(n) = bound.camera {
        if let Some(s) = slot_of(n, &mut anim)? {
            anim.attach_camera(s);
        }
    }
    for (i, &n) in bound.lights.iter().enumerate() {
        if let Some(s) = slot_of(n, &mut anim)? {
            anim.attach_light(i, s);
        }
    }
    for mut c in channels {
        // Channels of nodes that carry nothing drawn move nothing.
        if let Some(s) = slot[c.node] {
            c.node = s;
            anim.add_channel(c).map_err(|e| anyhow!(e))?;
        }
    }
    if anim.channels.is_empty() {
        warnings.push("animations ignored: they move no mesh, camera or light".into());
        return Ok(None);
    }
    Ok(Some(anim))
}

/// An accessor's components as `f32`, read with bounds checks (the glTF
/// crate's reader slices without them). Only floats, and for rotations the
/// normalized integers glTF allows, decoded as the specification says.
pub(super) fn read_floats(
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
    width: usize,
    rotation: bool,
) -> Result<Vec<f32>, String> {
    use gltf::accessor::DataType;
    let what = format!("accessor {}", acc.index());
    let n = acc.dimensions().multiplicity();
    if n != width {
        return Err(format!(
            "{what} is {:?}; it must be {}",
            acc.dimensions(),
            ["SCALAR", "VEC2", "VEC3", "VEC4"][width - 1]
        ));
    }
    let ty = acc.data_type();
    let decode: fn(&[u8]) -> f32 = match (ty, rotation && acc.normalized()) {
        (DataType::F32, _) => |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::I8, true) => |b| (b[0] as i8 as f32 / 127.0).max(-1.0),
        (DataType::U8, true) => |b| b[0] as f32 / 255.0,
        (DataType::I16, true) => |b| (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
        (DataType::U16, true) => |b| u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
        _ => {
            return Err(format!(
                "{what} has component type {ty:?}{}: animation keys must be floats{}",
                if acc.normalized() {
                    " (normalized)"
                } else {
                    ""
                },
                if rotation {
                    " or normalized integers"
                } else {
                    ""
                }
            ))
        }
    };
    let count = acc.count();
    if count > MAX_KEYS {
        return Err(format!(
            "{what} has {count} elements; isr reads at most {MAX_KEYS}"
        ));
    }
    let size = ty.size();
    let elem = size * n;
    let read = |bytes: &[u8], out: &mut [f32]| {
        for (c, o) in out.iter_mut().enumerate() {
            *o = decode(&bytes[c * size..(c + 1) * size]);
        }
    };
    let mut out = vec![0f32; count * n];
    // Without a buffer view the elements are zeros (sparse ones replaced below).
    if let Some(view) = acc.view() {
        let data = view_bytes(&view, buffers)?;
        let stride = view.stride().unwrap_or(elem);
        for (i, o) in out.chunks_exact_mut(n).enumerate() {
            let bytes = element(data, acc.offset(), i, stride, elem).ok_or_else(|| {
                format!(
                    "{what}: element {i} lies outside buffer view {}",
                    view.index()
                )
            })?;
            read(bytes, o);
        }
    }
    if let Some(sparse) = acc.sparse() {
        let (indices, values) = (sparse.indices(), sparse.values());
        let index_data = view_bytes(&indices.view(), buffers)?;
        let value_data = view_bytes(&values.view(), buffers)?;
        let isize = indices.index_type().size();
        for j in 0..sparse.count().min(count) {
            let b = element(index_data, indices.offset(), j, isize, isize)
                .ok_or_else(|| format!("{what}: sparse index {j} lies outside its buffer view"))?;
            let index = match isize {
                1 => b[0] as usize,
                2 => u16::from_le_bytes([b[0], b[1]]) as usize,
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
            };
            let v = element(value_data, values.offset(), j, elem, elem)
                .ok_or_else(|| format!("{what}: sparse value {j} lies outside its buffer view"))?;
            let o = out.get_mut(index * n..(index + 1) * n).ok_or_else(|| {
                format!("{what}: sparse index {index} is out of range for {count} elements")
            })?;
            read(v, o);
        }
    }
    Ok(out)
}

/// Bytes of element `i` (`len` bytes every `stride` from `offset`), if they lie in `data`.
pub(super) fn element(
    data: &[u8],
    offset: usize,
    i: usize,
    stride: usize,
    len: usize,
) -> Option<&[u8]> {
    let start = i.checked_mul(stride)?.checked_add(offset)?;
    data.get(start..start.checked_add(len)?)
}

pub(super) fn view_bytes<'b>(
    view: &gltf::buffer::View,
    buffers: &'b [Vec<u8>],
) -> Result<&'b [u8], String> {
    buffers
        .get(view.buffer().index())
        .and_then(|b| b.get(view.offset()..view.offset().checked_add(view.length())?))
        .ok_or_else(|| {
            format!(
                "buffer view {} lies outside buffer {}",
                view.index(),
                view.buffer().index()
            )
        })
}

/// Names the animation and channel when the glTF crate rejected a file for an
/// animation's reference; `None` when the problem lies elsewhere.
pub fn explain_invalid(bytes: &[u8]) -> Option<anyhow::Error> {
    let root = gltf::Gltf::from_slice_without_validation(bytes)
        .ok()?
        .document
        .into_json();
    check_references(&root).err()
}

/// Every channel's sampler, target node and path, and its sampler's
/// interpolation and accessors exist. The glTF crate validates samplers but
/// not channel targets, and its accessors unwrap.
pub(super) fn check_references(root: &gltf::json::Root) -> Result<()> {
    use gltf::json::validation::Checked;
    for (a, anim) in root.animations.iter().enumerate() {
        for (c, ch) in anim.channels.iter().enumerate() {
            let label = label(a, anim.name.as_deref(), c);
            let s = ch.sampler.value();
            let Some(sampler) = anim.samplers.get(s) else {
                bail!(
                    "{label} uses sampler {s}, which does not exist (the animation has {} samplers)",
                    anim.samplers.len()
                );
            };
            let node = ch.target.node.value();
            if node >= root.nodes.len() {
                bail!(
                    "{label} targets node {node}, which does not exist (the file has {} nodes)",
                    root.nodes.len()
                );
            }
            if let Checked::Invalid = ch.target.path {
                bail!("{label}: the target path is not translation, rotation, scale or weights");
            }
            if let Checked::Invalid = sampler.interpolation {
                bail!("{label}: sampler {s}'s interpolation is not STEP, LINEAR or CUBICSPLINE");
            }
            for (what, i) in [("input", sampler.input), ("output", sampler.output)] {
                if i.value() >= root.accessors.len() {
                    bail!(
                        "{label}: the {what} accessor {} of sampler {s} does not exist (the file has {} accessors)",
                        i.value(),
                        root.accessors.len()
                    );
                }
            }
        }
    }
    Ok(())
}
