//! Building glTF and GLB files for the loader's robustness tests and the fuzzer.
#![allow(dead_code)]

use base64::Engine as _;
use serde_json::{json, Value};
use std::path::PathBuf;

/// A fresh empty folder under the system temp dir.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("isr-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The built-in Cornell box as glTF JSON (one embedded base64 buffer).
pub fn cornell_json() -> Value {
    let text = isr::scene::export::to_gltf_json(&isr::scene::cornell::cornell_box()).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The bytes of the Cornell box's embedded buffer.
pub fn cornell_bin(doc: &Value) -> Vec<u8> {
    let uri = doc["buffers"][0]["uri"].as_str().unwrap();
    base64::engine::general_purpose::STANDARD
        .decode(uri.split_once(',').unwrap().1)
        .unwrap()
}

pub fn data_uri(bytes: &[u8]) -> String {
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// A GLB: 12-byte header, JSON chunk (space-padded), optional BIN chunk.
pub fn glb(doc: &Value, bin: Option<&[u8]>) -> Vec<u8> {
    let mut json = serde_json::to_vec(doc).unwrap();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(0u32.to_le_bytes()); // total length, patched below
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    if let Some(bin) = bin {
        let mut bin = bin.to_vec();
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&bin);
    }
    let len = out.len() as u32;
    out[8..12].copy_from_slice(&len.to_le_bytes());
    out
}

pub fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// One triangle (indexed, u16), a spot light and a camera, all in buffer 0
/// whose bytes are returned; the caller sets the buffer's `uri` or uses a GLB.
pub fn triangle_doc() -> (Value, Vec<u8>) {
    let mut bin = f32_bytes(&[0., 0., 0., 1., 0., 0., 0., 0., -1.]);
    bin.extend([0u8, 0, 1, 0, 2, 0, 0, 0]); // u16 indices, padded to 4
    let doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"camera": 0, "translation": [0.3, 2.0, 2.0]},
            {"extensions": {"KHR_lights_punctual": {"light": 0}},
             "matrix": [1,0,0,0, 0,0,-1,0, 0,1,0,0, 0.3,1.0,-0.3,1]}
        ],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "spot", "intensity": 5.0, "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}
        ]}},
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.05}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, -1], "max": [1, 0, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6}
        ],
        "buffers": [{"byteLength": bin.len()}]
    });
    (doc, bin)
}

/// `levels` nodes each listing the next one twice, the last holding a mesh:
/// 2^levels instances from a file of a few KB.
pub fn node_dag(levels: usize) -> Value {
    let (mut doc, bin) = triangle_doc();
    doc["buffers"][0]["uri"] = json!(data_uri(&bin));
    let mut nodes = doc["nodes"].as_array().unwrap().clone();
    let first = nodes.len();
    for k in 0..levels {
        let next = first + k + 1;
        nodes.push(if k + 1 < levels {
            json!({"children": [next, next]})
        } else {
            json!({"mesh": 0})
        });
    }
    doc["nodes"] = json!(nodes);
    doc["scenes"][0]["nodes"] = json!([first, 1, 2]);
    doc
}

/// A PNG that claims `w` x `h` in its header and has no pixel data (an
/// empty IDAT): enough for a header read, nothing to decode.
pub fn png_header_only(w: u32, h: u32) -> Vec<u8> {
    let mut ihdr = Vec::new();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 6, 0, 0, 0]); // 8-bit RGBA, deflate, no filter, no interlace
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    for (ty, data) in [(b"IHDR", &ihdr[..]), (b"IDAT", &[][..]), (b"IEND", &[][..])] {
        out.extend((data.len() as u32).to_be_bytes());
        let mut body = ty.to_vec();
        body.extend(data);
        out.extend(&body);
        out.extend(crc32(&body).to_be_bytes());
    }
    out
}

fn crc32(data: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in data {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}
