//! Writes a [`Scene`] as a self-contained glTF 2.0 file (buffers embedded as
//! base64). Used to produce `assets/cornell.gltf` from the built-in scene.

use super::animation::{Animation, Local, Parent, Property};
use super::Scene;
use anyhow::{bail, Result};
use base64::Engine as _;
use glam::{Mat4, Vec3};
use serde_json::{json, Value};

fn push_aligned(bin: &mut Vec<u8>, data: &[u8]) -> usize {
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let offset = bin.len();
    bin.extend_from_slice(data);
    offset
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
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut meshes = Vec::new();
    let mut add = |bin: &mut Vec<u8>,
                   bytes: &[u8],
                   count: usize,
                   ty: &str,
                   comp: u32,
                   extra: Value| {
        let offset = push_aligned(bin, bytes);
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}));
        let mut acc = json!({"bufferView": views.len() - 1, "componentType": comp, "count": count, "type": ty});
        if let (Value::Object(a), Value::Object(e)) = (&mut acc, extra) {
            a.extend(e);
        }
        accessors.push(acc);
        accessors.len() - 1
    };
    for m in &scene.meshes {
        let pos: Vec<f32> = m.vertices.iter().flat_map(|v| v.position).collect();
        let nrm: Vec<f32> = m.vertices.iter().flat_map(|v| v.normal).collect();
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for v in &m.vertices {
            lo = lo.min(Vec3::from(v.position));
            hi = hi.max(Vec3::from(v.position));
        }
        let bytes = |f: &[f32]| f.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let p = add(
            &mut bin,
            &bytes(&pos),
            m.vertices.len(),
            "VEC3",
            5126,
            json!({"min": lo.to_array(), "max": hi.to_array()}),
        );
        let n = add(
            &mut bin,
            &bytes(&nrm),
            m.vertices.len(),
            "VEC3",
            5126,
            json!({}),
        );
        let idx: Vec<u8> = m.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let i = add(&mut bin, &idx, m.indices.len(), "SCALAR", 5125, json!({}));
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
    let light_node = json!({"name": "light", "extensions": {"KHR_lights_punctual": {"light": 0}}});
    let camera_node = json!({"name": "camera", "camera": 0});
    let mut animations = vec![];
    let (mut light_node, mut camera_node) = (Some(light_node), Some(camera_node));
    if let Some(a) = &scene.animation {
        animations.push(animation_json(
            a,
            scene.instances.len(),
            &mut nodes,
            &mut roots,
            &mut light_node,
            &mut camera_node,
            &mut |bin, bytes, count, ty, extra| add(bin, bytes, count, ty, 5126, extra),
            &mut bin,
        ));
    }
    let l = &scene.light;
    if let Some(mut n) = light_node {
        n["matrix"] = json!(looking_along(l.position, l.direction).to_cols_array());
        nodes.push(n);
        roots.push(nodes.len() - 1);
    }
    if let Some(mut n) = camera_node {
        n["matrix"] = json!(scene.camera.world_from_camera.to_cols_array());
        nodes.push(n);
        roots.push(nodes.len() - 1);
    }
    let mut light = json!({"type": "spot", "color": l.color.to_array(), "intensity": l.intensity,
        "spot": {"innerConeAngle": l.inner_cone, "outerConeAngle": l.outer_cone}});
    if let Some(r) = l.range {
        light["range"] = json!(r);
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "isr export-builtin"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [light]}},
        "scene": 0,
        "scenes": [{"name": scene.name, "nodes": roots}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": scene.camera.yfov, "znear": scene.camera.znear}}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bin))}],
    });
    if !animations.is_empty() {
        doc["animations"] = json!(animations);
    }
    Ok(serde_json::to_string_pretty(&doc)?)
}

type AddAccessor<'a> = dyn FnMut(&mut Vec<u8>, &[u8], usize, &str, Value) -> usize + 'a;

/// Writes the animation's nodes (TRS where animated) and one glTF animation
/// with a sampler per channel. Instances the animation moves become children
/// without a transform of their node (`nodes[i]` stays instance `i`); the
/// light and camera, when moved, sit on their node itself (taken from
/// `light`/`camera`).
fn animation_json(
    a: &Animation,
    instances: usize,
    nodes: &mut Vec<Value>,
    roots: &mut Vec<usize>,
    light: &mut Option<Value>,
    camera: &mut Option<Value>,
    add: &mut AddAccessor,
    bin: &mut Vec<u8>,
) -> Value {
    let mut ids = Vec::with_capacity(a.nodes.len());
    let mut children: Vec<(usize, usize)> = vec![];
    for n in &a.nodes {
        let node = match n.local {
            Local::Fixed(m) => json!({"matrix": m.to_cols_array()}),
            Local::Animated(t) => json!({"translation": t.translation.to_array(),
                "rotation": t.rotation.to_array(), "scale": t.scale.to_array()}),
        };
        nodes.push(node);
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
        // The instance nodes come first; an index past them moves nothing.
        if let (true, Value::Object(node)) = (instance < instances, &mut nodes[instance]) {
            node.remove("matrix");
            roots.retain(|&r| r != instance);
            children.push((ids[n], instance));
        }
    }
    for (moved, slot) in [(a.light, light), (a.camera, camera)] {
        let Some(n) = moved else { continue };
        if let (Some(Value::Object(fields)), Value::Object(node)) =
            (slot.take(), &mut nodes[ids[n]])
        {
            node.extend(fields);
        }
    }
    for (parent, child) in children {
        match nodes[parent].get_mut("children") {
            Some(Value::Array(c)) => c.push(json!(child)),
            _ => nodes[parent]["children"] = json!([child]),
        }
    }
    let floats =
        |v: &mut dyn Iterator<Item = f32>| v.flat_map(f32::to_le_bytes).collect::<Vec<u8>>();
    let mut samplers = vec![];
    let mut channels = vec![];
    for c in &a.channels {
        let (lo, hi) = (c.times[0], c.times[c.times.len() - 1]);
        let input = add(
            bin,
            &floats(&mut c.times.iter().copied()),
            c.times.len(),
            "SCALAR",
            json!({"min": [lo], "max": [hi]}),
        );
        let width = if c.property == Property::Rotation {
            4
        } else {
            3
        };
        let output = add(
            bin,
            &floats(
                &mut c
                    .values
                    .iter()
                    .flat_map(|v| v.to_array().into_iter().take(width)),
            ),
            c.values.len(),
            if width == 4 { "VEC4" } else { "VEC3" },
            json!({}),
        );
        samplers.push(
            json!({"input": input, "output": output, "interpolation": c.interpolation.name()}),
        );
        channels.push(json!({"sampler": samplers.len() - 1,
            "target": {"node": ids[c.node], "path": c.property.name()}}));
    }
    json!({"name": "animation", "samplers": samplers, "channels": channels})
}
