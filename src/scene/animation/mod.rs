//! Keyframe animation of node translation, rotation and scale (glTF 2.0
//! `animations`), and the part of the node hierarchy it moves.
//!
//! A [`Scene`](super::Scene) keeps only the nodes an animation can move and that
//! carry something `isr` draws: each animated node, the nodes between it and the
//! instances, camera and light below it, each with its local rest transform and
//! its parent. Everything above the topmost animated node is static and folded
//! into one matrix. All channels of all animations of a file play together on
//! one clock; time clamps to each channel's first and last keyframe.

use super::FrameState;
use anyhow::{anyhow, bail, Result};
use glam::{Mat4, Quat, Vec3, Vec4};

/// A node's local transform as glTF animates it: `T * R * S`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trs {
    pub translation: Vec3,
    /// Unit quaternion.
    pub rotation: Quat,
    pub scale: Vec3,
}

impl Trs {
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

/// The node property a channel animates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Property {
    Translation,
    Rotation,
    Scale,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The value of the latest key at or before the time.
    Step,
    /// Linear; rotations are spherically interpolated along the shorter arc.
    Linear,
    /// Cubic Hermite spline; each key has an in-tangent, a value and an out-tangent.
    CubicSpline,
}

impl Property {
    /// The glTF `target.path`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Translation => "translation",
            Self::Rotation => "rotation",
            Self::Scale => "scale",
        }
    }
}

impl Interpolation {
    /// The glTF `sampler.interpolation`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Step => "STEP",
            Self::Linear => "LINEAR",
            Self::CubicSpline => "CUBICSPLINE",
        }
    }
}

/// One keyframe track of one property of one node of an [`Animation`].
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    pub(super) node: usize,
    pub(super) property: Property,
    pub(super) interpolation: Interpolation,
    pub(super) times: Vec<f32>,
    /// Per key a vector (w unused) or a quaternion (xyzw); CUBICSPLINE keys
    /// are three entries: in-tangent, value, out-tangent.
    pub(super) values: Vec<Vec4>,
}

impl Channel {
    /// Checks the keys (at least one, finite, strictly increasing times, one
    /// value per time or three for CUBICSPLINE, finite values, rotations of
    /// non-zero length) and normalizes rotation values.
    pub fn new(
        node: usize,
        property: Property,
        interpolation: Interpolation,
        times: Vec<f32>,
        mut values: Vec<Vec4>,
    ) -> Result<Self, String> {
        if times.is_empty() {
            return Err("the sampler has no keyframes".into());
        }
        if let Some(i) = times.iter().position(|t| !t.is_finite()) {
            return Err(format!("keyframe time {i} is {}", times[i]));
        }
        if let Some(i) = (1..times.len()).find(|&i| times[i] <= times[i - 1]) {
            return Err(format!(
                "keyframe times must increase strictly, but time {i} ({} s) is not after time {} ({} s)",
                times[i],
                i - 1,
                times[i - 1]
            ));
        }
        let per_key = if interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
        if values.len() != per_key * times.len() {
            return Err(if per_key == 3 {
                format!(
                    "the CUBICSPLINE output has {} values for {} keyframe times; it needs three per time (in-tangent, value, out-tangent), {}",
                    values.len(),
                    times.len(),
                    3 * times.len()
                )
            } else {
                format!(
                    "the input has {} keyframe times but the output has {} values ({} needs one value per time)",
                    times.len(),
                    values.len(),
                    interpolation.name()
                )
            });
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(format!("output value {i} is not finite: {}", values[i]));
        }
        if property == Property::Rotation {
            // Tangents are derivatives, not rotations: only the values are unit.
            for (i, v) in values.iter_mut().enumerate() {
                if per_key == 1 || i % 3 == 1 {
                    *v = v.try_normalize().ok_or_else(|| {
                        format!("rotation key {} is a zero quaternion", i / per_key)
                    })?;
                }
            }
        }
        Ok(Self {
            node,
            property,
            interpolation,
            times,
            values,
        })
    }

    /// The time of the last keyframe.
    pub fn end(&self) -> f32 {
        self.times[self.times.len() - 1]
    }

    /// The channel's value at time `t` (a quaternion's xyzw for rotations).
    pub fn sample(&self, t: f32) -> Vec4 {
        let cubic = self.interpolation == Interpolation::CubicSpline;
        let value = |k: usize| self.values[if cubic { 3 * k + 1 } else { k }];
        // Keys at or before t; 0 also for a NaN time.
        let after = self.times.partition_point(|&x| x <= t);
        if after == 0 {
            return value(0);
        }
        if after == self.times.len() {
            return value(after - 1);
        }
        let k = after - 1;
        let dt = self.times[k + 1] - self.times[k];
        let s = (t - self.times[k]) / dt;
        let rotation = self.property == Property::Rotation;
        match self.interpolation {
            Interpolation::Step => value(k),
            Interpolation::Linear if rotation => slerp(value(k), value(k + 1), s),
            Interpolation::Linear => value(k).lerp(value(k + 1), s),
            Interpolation::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                // glTF 2.0 appendix C: out-tangent of k and in-tangent of k + 1,
                // both scaled by the interval.
                let v = value(k) * (2.0 * s3 - 3.0 * s2 + 1.0)
                    + self.values[3 * k + 2] * (dt * (s3 - 2.0 * s2 + s))
                    + value(k + 1) * (-2.0 * s3 + 3.0 * s2)
                    + self.values[3 * (k + 1)] * (dt * (s3 - s2));
                if rotation {
                    v.normalize_or(value(k))
                } else {
                    v
                }
            }
        }
    }
}

/// Normalized spherical interpolation of unit quaternions (xyzw) along the
/// shorter arc: `b` is negated when the two are more than 90 degrees apart in
/// 4D, since `q` and `-q` are the same rotation.
pub fn slerp(a: Vec4, b: Vec4, s: f32) -> Vec4 {
    let mut cos = a.dot(b);
    let b = if cos < 0.0 {
        cos = -cos;
        -b
    } else {
        b
    };
    // Nearly equal: sin(theta) vanishes, and linear is as good.
    if cos > 0.9995 {
        return a.lerp(b, s).normalize();
    }
    let theta = cos.min(1.0).acos();
    let v = (a * ((1.0 - s) * theta).sin() + b * (s * theta).sin()) / theta.sin();
    v.normalize()
}

/// Where a node's parent transform comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Parent {
    /// An earlier node of the same [`Animation`].
    Node(usize),
    /// A static world transform (identity for a root of the scene).
    Fixed(Mat4),
}

/// A node's local transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Local {
    /// Not animated; a matrix, since a glTF matrix may shear.
    Fixed(Mat4),
    /// The rest pose; channels replace its properties.
    Animated(Trs),
}

#[derive(Clone, Debug, PartialEq)]
pub(super) struct Node {
    pub(super) parent: Parent,
    pub(super) local: Local,
}

/// The animated part of a scene: nodes (parents before children), channels,
/// and which `Scene::instances` entries, camera and light hang under which
/// node. What no node carries stays where the scene put it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Animation {
    pub(super) nodes: Vec<Node>,
    pub(super) channels: Vec<Channel>,
    /// (index into `Scene::instances`, node).
    pub(super) instances: Vec<(usize, usize)>,
    pub(super) camera: Option<usize>,
    pub(super) light: Option<usize>,
}

impl Animation {
    /// Adds a node; returns its index.
    pub fn add_node(&mut self, parent: Parent, local: Local) -> Result<usize, String> {
        if let Parent::Node(p) = parent {
            if p >= self.nodes.len() {
                return Err(format!("parent node {p} must be added before its children"));
            }
        }
        self.nodes.push(Node { parent, local });
        Ok(self.nodes.len() - 1)
    }

    /// Adds a channel; its node must exist and have an animated (TRS) local transform.
    pub fn add_channel(&mut self, channel: Channel) -> Result<(), String> {
        match self.nodes.get(channel.node) {
            Some(Node {
                local: Local::Animated(_),
                ..
            }) => {
                self.channels.push(channel);
                Ok(())
            }
            Some(_) => Err(format!(
                "node {} has a fixed matrix and cannot be animated",
                channel.node
            )),
            None => Err(format!("node {} does not exist", channel.node)),
        }
    }

    /// Makes `Scene::instances[instance]` follow `node` (its world transform
    /// becomes the node's).
    pub fn attach_instance(&mut self, instance: usize, node: usize) {
        assert!(node < self.nodes.len(), "attach to a node that exists");
        self.instances.push((instance, node));
    }

    /// The camera's world transform becomes `node`'s.
    pub fn attach_camera(&mut self, node: usize) {
        assert!(node < self.nodes.len(), "attach to a node that exists");
        self.camera = Some(node);
    }

    /// The light sits at `node`'s origin and points along its -Z.
    pub fn attach_light(&mut self, node: usize) {
        assert!(node < self.nodes.len(), "attach to a node that exists");
        self.light = Some(node);
    }

    /// The latest keyframe time of any channel; `None` without channels.
    pub fn duration(&self) -> Option<f32> {
        self.channels.iter().map(Channel::end).reduce(f32::max)
    }

    /// Moves what hangs under the nodes to where the animation has it at `t`.
    pub fn apply(&self, t: f32, state: &mut FrameState) {
        let mut locals: Vec<Local> = self.nodes.iter().map(|n| n.local).collect();
        for c in &self.channels {
            if let Local::Animated(trs) = &mut locals[c.node] {
                let v = c.sample(t);
                match c.property {
                    Property::Translation => trs.translation = v.truncate(),
                    Property::Rotation => trs.rotation = Quat::from_vec4(v),
                    Property::Scale => trs.scale = v.truncate(),
                }
            }
        }
        let mut world: Vec<Mat4> = Vec::with_capacity(self.nodes.len());
        for (node, local) in self.nodes.iter().zip(&locals) {
            let parent = match node.parent {
                Parent::Node(p) => world[p],
                Parent::Fixed(m) => m,
            };
            let local = match local {
                Local::Fixed(m) => *m,
                Local::Animated(trs) => trs.matrix(),
            };
            world.push(parent * local);
        }
        for &(i, n) in &self.instances {
            if let Some(m) = state.instance_transforms.get_mut(i) {
                *m = world[n];
            }
        }
        if let Some(n) = self.camera {
            state.camera.world_from_camera = world[n];
        }
        if let Some(n) = self.light {
            let l = &mut state.light;
            l.position = world[n].transform_point3(Vec3::ZERO);
            // A node scaled to zero has no direction: keep the last one.
            l.direction = world[n]
                .transform_vector3(-Vec3::Z)
                .normalize_or(l.direction);
        }
    }
}

/// The rotation that turns a node's -Z (where glTF cameras and spot lights
/// point) to `direction`, keeping its +Y up as far as possible.
pub fn rotation_looking_along(direction: Vec3) -> Quat {
    let d = direction.normalize();
    let up = if d.dot(Vec3::Y).abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let x = up.cross(-d).normalize();
    let y = (-d).cross(x);
    Quat::from_mat3(&glam::Mat3::from_cols(x, y, -d))
}

/// Which glTF node each thing the loader made came from.
#[derive(Clone, Debug, Default)]
pub struct NodeBindings {
    /// The node of each `Scene::instances` entry, in order.
    pub instances: Vec<usize>,
    pub camera: Option<usize>,
    pub light: Option<usize>,
}

/// Keyframe counts above this are refused, so that a corrupt accessor count
/// cannot exhaust memory (2^20 keys is hours of keys at 60 per second).
const MAX_KEYS: usize = 1 << 20;

fn label(index: usize, name: Option<&str>, channel: usize) -> String {
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
                    .map_err(|e| anyhow!("{label}: {e}"))?,
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
    // World transform of a static node, composed root first as the loader does.
    let rest_world = |k: usize| {
        let mut chain = vec![k];
        while let Some(p) = parent[chain[chain.len() - 1]] {
            chain.push(p);
        }
        chain
            .iter()
            .rev()
            .fold(Mat4::IDENTITY, |w, &n| w * local(n))
    };

    let mut anim = Animation::default();
    let mut slot: Vec<Option<usize>> = vec![None; count];
    // The animation node that carries glTF node `n`, created with its
    // affected ancestors on first use; `None` when nothing above `n` moves.
    let mut slot_of = |n: usize, anim: &mut Animation| -> Result<Option<usize>> {
        let mut chain = vec![];
        let mut m = Some(n);
        let mut above = loop {
            let Some(k) = m else {
                break Parent::Fixed(Mat4::IDENTITY);
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
    if let Some(n) = bound.light {
        if let Some(s) = slot_of(n, &mut anim)? {
            anim.attach_light(s);
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
fn read_floats(
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
fn element(data: &[u8], offset: usize, i: usize, stride: usize, len: usize) -> Option<&[u8]> {
    let start = i.checked_mul(stride)?.checked_add(offset)?;
    data.get(start..start.checked_add(len)?)
}

fn view_bytes<'b>(view: &gltf::buffer::View, buffers: &'b [Vec<u8>]) -> Result<&'b [u8], String> {
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
fn check_references(root: &gltf::json::Root) -> Result<()> {
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

#[cfg(test)]
mod tests;
