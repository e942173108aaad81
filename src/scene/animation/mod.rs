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

mod load;
pub use load::{explain_invalid, from_gltf};

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
    /// How messages name it: "animation 0 (walk) channel 2" from a file.
    pub(super) label: String,
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
                    // Scaled by its largest component first: (1e-30, 0, 0,
                    // 1e-30) is a rotation whose squared length underflows.
                    let largest = v.abs().max_element();
                    *v = (*v / largest).try_normalize().ok_or_else(|| {
                        format!("rotation key {} is a zero quaternion", i / per_key)
                    })?;
                }
            }
        }
        let label = format!("the {} channel of node {node}", property.name());
        Ok(Self {
            node,
            property,
            interpolation,
            times,
            values,
            label,
        })
    }

    /// This channel, named `label` in messages ("animation 0 (walk) channel 2").
    pub fn labelled(self, label: String) -> Self {
        Self { label, ..self }
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
    /// (index into `Scene::lights`, node).
    pub(super) lights: Vec<(usize, usize)>,
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

    /// Light `light` (an index into `Scene::lights`) sits at `node`'s origin
    /// and points along its -Z.
    pub fn attach_light(&mut self, light: usize, node: usize) {
        assert!(node < self.nodes.len(), "attach to a node that exists");
        self.lights.push((light, node));
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
            // Without scale, as the loader places it; a pose with no
            // orientation is NaN, which `Scene::pose_at` refuses.
            state.camera.world_from_camera = crate::scene::rigid(world[n]).unwrap_or(Mat4::NAN);
        }
        for &(i, n) in &self.lights {
            let Some(l) = state.lights.get_mut(i) else {
                continue;
            };
            l.position = world[n].transform_point3(Vec3::ZERO);
            // A node scaled to zero has no direction: keep the last one.
            l.direction = world[n]
                .transform_vector3(-Vec3::Z)
                .normalize_or(l.direction);
        }
    }
}

/// What an animation moves, for messages that name the channels behind it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Moved {
    Instance(usize),
    Camera,
    Light(usize),
}

impl Animation {
    /// The channels that move `what` (those of its node and of the nodes
    /// above it), each described with its value at `t`; empty when the
    /// animation does not move it.
    pub fn channels_moving(&self, what: Moved, t: f32) -> Vec<String> {
        let node = match what {
            Moved::Instance(i) => self.instances.iter().find(|e| e.0 == i).map(|e| e.1),
            Moved::Camera => self.camera,
            Moved::Light(i) => self.lights.iter().find(|e| e.0 == i).map(|e| e.1),
        };
        let mut chain = vec![];
        let mut n = node;
        while let Some(k) = n {
            chain.push(k);
            n = match self.nodes[k].parent {
                Parent::Node(p) => Some(p),
                Parent::Fixed(_) => None,
            };
        }
        self.channels
            .iter()
            .filter(|c| chain.contains(&c.node))
            .map(|c| {
                let v = c.sample(t);
                let v = match c.property {
                    Property::Rotation => format!("{:?}", v.to_array()),
                    _ => format!("{:?}", v.truncate().to_array()),
                };
                format!("{} ({} {v} at this time)", c.label, c.property.name())
            })
            .collect()
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
    /// The node of each `Scene::lights` entry, in order (empty for the default light).
    pub lights: Vec<usize>,
}

#[cfg(test)]
mod tests;
