//! Writes a [`Scene`] as a self-contained glTF 2.0 file (buffers embedded as
//! base64). Used to produce `assets/cornell.gltf` from the built-in scene.

use super::animation::{Animation, Local, Parent, Property};
use super::Scene;
use anyhow::{bail, Result};
use base64::Engine as _;
use glam::{Mat4, Vec3};
use serde_json::{json, Value};

/// The one buffer, its views and the accessors, as they are written.
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    /// Appends `data` (4-byte aligned) with a view and an accessor; `extra`
    /// fields (min, max) go into the accessor. Returns the accessor's index.
    fn add(&mut self, data: &[u8], count: usize, ty: &str, comp: u32, extra: Value) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(data);
        self.views
            .push(json!({"buffer": 0, "byteOffset": offset, "byteLength": data.len()}));
        let mut acc = json!({"bufferView": self.views.len() - 1, "componentType": comp, "count": count, "type": ty});
        if let (Value::Object(a), Value::Object(e)) = (&mut acc, extra) {
            a.extend(e);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    fn floats(
        &mut self,
        f: impl Iterator<Item = f32>,
        count: usize,
        ty: &str,
        extra: Value,
    ) -> usize {
        let data: Vec<u8> = f.flat_map(f32::to_le_bytes).collect();
        self.add(&data, count, ty, 5126, extra)
    }
}

/// The node matrix that makes local -Z point along `dir` from `pos`.
fn looking_along(pos: Vec3, dir: Vec3) -> Mat4 {
    let up = if dir.normalize().dot(Vec3::Y).abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    Mat4::look_at_rh(pos, pos + dir, up).inverse()
}

pub fn to_gltf_json(scene: &Scene) -> Result<String> {
    if !scene.textures.is_empty() {
        bail!("exporting textured scenes is not supported");
    }
    if scene.origin != glam::DVec3::ZERO {
        // Its positions are relative to the origin, which glTF's f32
        // transforms would round again.
        bail!("exporting a scene stored relative to an origin of its own (far from the world's origin) is not supported");
    }
    let mut bin = Bin::default();
    let mut meshes = Vec::new();
    for m in &scene.meshes {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for v in &m.vertices {
            lo = lo.min(Vec3::from(v.position));
            hi = hi.max(Vec3::from(v.position));
        }
        let count = m.vertices.len();
        let p = bin.floats(
            m.vertices.iter().flat_map(|v| v.position),
            count,
            "VEC3",
            json!({"min": lo.to_array(), "max": hi.to_array()}),
        );
        let n = bin.floats(
            m.vertices.iter().flat_map(|v| v.normal),
            count,
            "VEC3",
            json!({}),
        );
        let idx: Vec<u8> = m.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let i = bin.add(&idx, m.indices.len(), "SCALAR", 5125, json!({}));
        meshes.push(json!({"name": m.name, "primitives": [{
            "attributes": {"POSITION": p, "NORMAL": n}, "indices": i, "material": m.material}]}));
    }
    let materials: Vec<Value> = scene
        .materials
        .iter()
        .map(|m| json!({"name": m.name, "doubleSided": m.double_sided,
            "pbrMetallicRoughness": {"baseColorFactor": m.base_color.to_array(), "metallicFactor": 0.0, "roughnessFactor": 1.0}}))
        .collect();
    let mut nodes: Vec<Value> = scene
        .instances
        .iter()
        .map(|i| json!({"mesh": i.mesh, "matrix": i.world_from_object.to_cols_array()}))
        .collect();
    let mut roots: Vec<usize> = (0..nodes.len()).collect();
    let mut animations = vec![];
    let (mut light_at, mut camera_at) = (vec![], None);
    if let Some(a) = &scene.animation {
        let (anim, l, c) = animation_json(a, &mut nodes, &mut roots, &mut bin);
        animations.push(anim);
        (light_at, camera_at) = (l, c);
    }
    let mut place = |at: Option<usize>, fields: Value, matrix: Mat4| match at {
        // On the animated node that moves it.
        Some(id) => {
            if let (Value::Object(node), Value::Object(f)) = (&mut nodes[id], fields) {
                node.extend(f);
            }
        }
        None => {
            let mut node = fields;
            node["matrix"] = json!(matrix.to_cols_array());
            nodes.push(node);
            roots.push(nodes.len() - 1);
        }
    };
    for (i, l) in scene.lights.iter().enumerate() {
        let at = light_at
            .iter()
            .find(|&&(light, _)| light == i)
            .map(|&(_, n)| n);
        place(
            at,
            json!({"name": format!("light {i}"), "extensions": {"KHR_lights_punctual": {"light": i}}}),
            looking_along(l.position, l.direction),
        );
    }
    place(
        camera_at,
        json!({"name": "camera", "camera": 0}),
        scene.camera.world_from_camera,
    );
    let lights: Vec<Value> = scene
        .lights
        .iter()
        .map(|l| {
            let mut light = json!({"type": l.kind.name(), "color": l.color.to_array(), "intensity": l.intensity});
            if l.kind == crate::scene::LightKind::Spot {
                light["spot"] =
                    json!({"innerConeAngle": l.inner_cone, "outerConeAngle": l.outer_cone});
            }
            if let (Some(r), false) = (l.range, l.kind == crate::scene::LightKind::Directional) {
                light["range"] = json!(r);
            }
            light
        })
        .collect();
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "isr export-builtin"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "scene": 0,
        "scenes": [{"name": scene.name, "nodes": roots}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": scene.camera.yfov, "znear": scene.camera.znear}}],
        "accessors": bin.accessors,
        "bufferViews": bin.views,
        "buffers": [{"byteLength": bin.bytes.len(), "uri": format!("data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bin.bytes))}],
    });
    if !animations.is_empty() {
        doc["animations"] = json!(animations);
    }
    Ok(serde_json::to_string_pretty(&doc)?)
}

/// Writes the animation's nodes (TRS where animated) and one glTF animation
/// with a sampler per channel. Instances the animation moves become children
/// without a transform of their node (`nodes[i]` is instance `i` on entry).
/// Returns the animation and the nodes that carry lights (light index, node)
/// and the camera when it moves them.
fn animation_json(
    a: &Animation,
    nodes: &mut Vec<Value>,
    roots: &mut Vec<usize>,
    bin: &mut Bin,
) -> (Value, Vec<(usize, usize)>, Option<usize>) {
    let instances = nodes.len();
    let mut ids = Vec::with_capacity(a.nodes.len());
    let mut children: Vec<(usize, usize)> = vec![];
    for n in &a.nodes {
        nodes.push(match n.local {
            Local::Fixed(m) => json!({"matrix": m.to_cols_array()}),
            Local::Animated(t) => json!({"translation": t.translation.to_array(),
                "rotation": t.rotation.to_array(), "scale": t.scale.to_array()}),
        });
        let id = nodes.len() - 1;
        ids.push(id);
        match n.parent {
            Parent::Node(p) => children.push((ids[p], id)),
            Parent::Fixed(m) if m == Mat4::IDENTITY => roots.push(id),
            Parent::Fixed(m) => {
                nodes.push(json!({"matrix": m.to_cols_array(), "children": [id]}));
                roots.push(nodes.len() - 1);
            }
        }
    }
    for &(instance, n) in &a.instances {
        // An index past the scene's instances moves nothing.
        if let (true, Value::Object(node)) = (instance < instances, &mut nodes[instance]) {
            node.remove("matrix");
            roots.retain(|&r| r != instance);
            children.push((ids[n], instance));
        }
    }
    for (parent, child) in children {
        match nodes[parent].get_mut("children") {
            Some(Value::Array(c)) => c.push(json!(child)),
            _ => nodes[parent]["children"] = json!([child]),
        }
    }
    let mut samplers = vec![];
    let mut channels = vec![];
    for c in &a.channels {
        let (lo, hi) = (c.times[0], c.times[c.times.len() - 1]);
        let input = bin.floats(
            c.times.iter().copied(),
            c.times.len(),
            "SCALAR",
            json!({"min": [lo], "max": [hi]}),
        );
        let (width, ty) = match c.property {
            Property::Rotation => (4, "VEC4"),
            _ => (3, "VEC3"),
        };
        let values = c
            .values
            .iter()
            .flat_map(|v| v.to_array().into_iter().take(width));
        let output = bin.floats(values, c.values.len(), ty, json!({}));
        samplers.push(
            json!({"input": input, "output": output, "interpolation": c.interpolation.name()}),
        );
        channels.push(json!({"sampler": samplers.len() - 1,
            "target": {"node": ids[c.node], "path": c.property.name()}}));
    }
    let anim = json!({"name": "animation", "samplers": samplers, "channels": channels});
    let lights = a.lights.iter().map(|&(l, n)| (l, ids[n])).collect();
    (anim, lights, a.camera.map(|n| ids[n]))
}
