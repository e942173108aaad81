//! The one builder of glTF and GLB files, for the loader's tests, the
//! animation tests and the fuzzer: a document with its buffer 0 beside it
//! ([`Doc`]), the Cornell box and a one-triangle seed, node DAGs, PNGs
//! (whole, or a header that only claims a size), and writing and loading a
//! document from a folder.

use base64::Engine as _;
use isr::scene::{gltf_load, Scene};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A glTF document being built, with the bytes of its buffer 0 beside it:
/// views and accessors are appended to the document's lists and their bytes
/// to `bin`; [`Doc::embedded`] and [`Doc::glb`] make the file.
#[derive(Clone)]
pub struct Doc {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl Doc {
    /// A document with no views or accessors yet.
    pub fn empty() -> Doc {
        Doc {
            json: json!({"asset": {"version": "2.0"}, "bufferViews": [], "accessors": [],
                         "buffers": [{"byteLength": 0}]}),
            bin: vec![],
        }
    }

    /// The built-in Cornell box, its embedded buffer decoded into `bin`.
    pub fn cornell() -> Doc {
        let json = cornell_json();
        let bin = cornell_bin(&json);
        Doc { json, bin }
    }

    /// One triangle (indexed, u16), a spot light and a camera, all in buffer
    /// 0 (which names no `uri` yet).
    pub fn triangle() -> Doc {
        let mut bin = f32_bytes(&[0., 0., 0., 1., 0., 0., 0., 0., -1.]);
        bin.extend([0u8, 0, 1, 0, 2, 0, 0, 0]); // u16 indices, padded to 4
        let json = json!({
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
        Doc { json, bin }
    }

    /// Appends `bytes` (4-aligned) and a view of them; returns the view.
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let views = self.json["bufferViews"].as_array_mut().unwrap();
        views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        views.len() - 1
    }

    /// Appends accessor `a`; returns its index.
    pub fn accessor(&mut self, a: Value) -> usize {
        let accessors = self.json["accessors"].as_array_mut().unwrap();
        accessors.push(a);
        accessors.len() - 1
    }

    /// `bytes` as a new view and an accessor of `count` elements of `ty`
    /// and `component` over it; returns the accessor.
    pub fn data(&mut self, bytes: &[u8], count: usize, ty: &str, component: u32) -> usize {
        let view = self.view(bytes);
        self.accessor(json!({"bufferView": view, "componentType": component,
                             "count": count, "type": ty}))
    }

    /// FLOAT values of type `ty` (SCALAR, VEC2, VEC3 or VEC4).
    pub fn floats(&mut self, v: &[f32], ty: &str) -> usize {
        let width = match ty {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            _ => 4,
        };
        self.data(&f32_bytes(v), v.len() / width, ty, 5126)
    }

    /// The document with buffer 0 embedded as a base64 data URI.
    pub fn embedded(&self) -> Value {
        let mut doc = self.json.clone();
        doc["buffers"][0] = json!({"byteLength": self.bin.len(), "uri": data_uri(&self.bin)});
        doc
    }

    /// The document as a GLB reads it: buffer 0 is the binary chunk.
    pub fn glb_json(&self) -> Value {
        let mut doc = self.json.clone();
        doc["buffers"][0] = json!({"byteLength": self.bin.len()});
        doc
    }

    /// The GLB file.
    pub fn glb(&self) -> Vec<u8> {
        glb(&self.glb_json(), Some(&self.bin))
    }
}

/// The built-in Cornell box as glTF JSON (one embedded base64 buffer).
pub fn cornell_json() -> Value {
    let text = isr::scene::export::to_gltf_json(&isr::scene::cornell::cornell_box()).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// `scene` exported as glTF JSON.
pub fn exported(scene: &Scene) -> Value {
    serde_json::from_str(&isr::scene::export::to_gltf_json(scene).unwrap()).unwrap()
}

/// The bytes of the Cornell box's embedded buffer.
pub fn cornell_bin(doc: &Value) -> Vec<u8> {
    base64_data(doc["buffers"][0]["uri"].as_str().unwrap()).unwrap()
}

/// The bytes of a base64 data URI.
pub fn base64_data(uri: &str) -> Option<Vec<u8>> {
    base64::engine::general_purpose::STANDARD
        .decode(uri.split_once(',')?.1)
        .ok()
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
        while !bin.len().is_multiple_of(4) {
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

/// `levels` nodes each listing the next one twice, the last holding a mesh:
/// 2^levels instances from a file of a few KB.
pub fn node_dag(levels: usize) -> Value {
    let mut doc = Doc::triangle().embedded();
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

/// Material 0's base colour texture read from `image` (an image object:
/// `{"uri": ...}` or a buffer view).
pub fn with_texture(doc: &mut Value, image: Value) {
    doc["images"] = json!([image]);
    doc["textures"] = json!([{"source": 0}]);
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
}

/// The Cornell box without its camera and light nodes, under one root node
/// scaled by `scale` (the loader then fits a default light and camera).
pub fn cornell_scaled_without_camera_and_light(scale: f64) -> Value {
    let mut doc = cornell_json();
    let nodes = doc["nodes"].as_array_mut().unwrap();
    nodes.retain(|n| n.get("camera").is_none() && n.get("extensions").is_none());
    let n = nodes.len();
    nodes.push(json!({"children": (0..n).collect::<Vec<_>>(), "scale": [scale, scale, scale]}));
    doc["scenes"][0]["nodes"] = json!([n]);
    doc
}

/// An 8-bit RGB PNG of `w` x `h` pixels.
pub fn png(w: u32, h: u32, rgb: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    image::write_buffer_with_format(
        &mut std::io::Cursor::new(&mut out),
        rgb,
        w,
        h,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .unwrap();
    out
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

/// A sampler with keyframe `times` and flat `values` (VEC3, or VEC4 for
/// rotations), its accessors appended to `d`.
pub fn sampler(d: &mut Doc, interpolation: &str, times: &[f32], values: &[f32], ty: &str) -> Value {
    let input = d.floats(times, "SCALAR");
    if times.iter().all(|t| t.is_finite()) {
        d.json["accessors"][input]["min"] = json!([times[0]]);
        d.json["accessors"][input]["max"] = json!([times[times.len() - 1]]);
    }
    let output = d.floats(values, ty);
    json!({"input": input, "output": output, "interpolation": interpolation})
}

/// For the animation tests: a document with one triangle mesh, one perspective camera, one spot light,
/// `nodes` (roots are the nodes nobody lists as a child) and the animations
/// `animations` builds.
pub fn animated_doc(nodes: Value, animations: impl FnOnce(&mut Doc) -> Value) -> Value {
    let mut d = Doc::empty();
    let pos = d.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], "VEC3");
    d.json["accessors"][pos]["min"] = json!([0., 0., 0.]);
    d.json["accessors"][pos]["max"] = json!([1., 1., 0.]);
    let animations = animations(&mut d);
    let n = nodes.as_array().unwrap();
    let children: Vec<&Value> = n
        .iter()
        .filter_map(|x| x.get("children"))
        .flat_map(|c| c.as_array().unwrap())
        .collect();
    let roots: Vec<usize> = (0..n.len())
        .filter(|i| !children.contains(&&json!(i)))
        .collect();
    let mut doc = d.embedded();
    let fields = json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "intensity": 5.0,
            "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}]}},
        "scene": 0,
        "scenes": [{"nodes": roots}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.05}}],
        "animations": animations,
    });
    for (k, v) in fields.as_object().unwrap() {
        doc[k] = v.clone();
    }
    doc
}

/// Writes `doc` as `dir/scene.gltf`; returns the path.
pub fn write_scene(dir: &Path, doc: &Value) -> PathBuf {
    let p = dir.join("scene.gltf");
    std::fs::write(&p, serde_json::to_string(doc).unwrap()).unwrap();
    p
}

/// Writes `doc` into `dir` and loads it with the default options.
pub fn load(dir: &Path, doc: &Value) -> anyhow::Result<Scene> {
    gltf_load::load(&write_scene(dir, doc))
}

/// The message of a document that must not load.
pub fn load_error(dir: &Path, doc: &Value) -> String {
    match load(dir, doc) {
        Ok(_) => panic!("expected the document not to load"),
        Err(e) => format!("{e:#}"),
    }
}

/// [`load`] in a fresh folder named for the test (`super::temp_dir`).
pub fn load_in(name: &str, doc: &Value) -> anyhow::Result<Scene> {
    load(&super::temp_dir(name), doc)
}

/// [`load_error`] in a fresh folder named for the test.
pub fn load_error_in(name: &str, doc: &Value) -> String {
    load_error(&super::temp_dir(name), doc)
}
