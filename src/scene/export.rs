//! Writes a [`Scene`] as a self-contained glTF 2.0 file (buffers embedded as
//! base64). Used to produce `assets/cornell.gltf` from the built-in scene.

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
    let l = &scene.light;
    nodes.push(
        json!({"name": "light", "matrix": looking_along(l.position, l.direction).to_cols_array(),
        "extensions": {"KHR_lights_punctual": {"light": 0}}}),
    );
    nodes.push(json!({"name": "camera", "camera": 0, "matrix": scene.camera.world_from_camera.to_cols_array()}));
    let mut light = json!({"type": "spot", "color": l.color.to_array(), "intensity": l.intensity,
        "spot": {"innerConeAngle": l.inner_cone, "outerConeAngle": l.outer_cone}});
    if let Some(r) = l.range {
        light["range"] = json!(r);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "isr export-builtin"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [light]}},
        "scene": 0,
        "scenes": [{"name": scene.name, "nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": scene.camera.yfov, "znear": scene.camera.znear}}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bin))}],
    });
    Ok(serde_json::to_string_pretty(&doc)?)
}
