//! The fuzzer's mutations: a small deterministic generator, structural
//! changes to a glTF document (values, keys, node lists, sparse accessors)
//! and byte-level damage (flips, header words, truncation, insertion).

use crate::common::gltf::{base64_data, data_uri};
use serde_json::{json, Value};

/// SplitMix64: small, deterministic, good enough to pick mutations.
pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    pub fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
    pub fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.below(v.len())]
    }
}

/// Paths to every value in `doc` (object keys and array indices).
fn paths(doc: &Value) -> Vec<Vec<Value>> {
    let mut out = Vec::new();
    let mut stack = vec![(doc, Vec::new())];
    while let Some((v, path)) = stack.pop() {
        match v {
            Value::Object(m) => {
                for (k, c) in m {
                    let mut p = path.clone();
                    p.push(json!(k));
                    stack.push((c, p));
                }
            }
            Value::Array(a) => {
                for (i, c) in a.iter().enumerate() {
                    let mut p = path.clone();
                    p.push(json!(i));
                    stack.push((c, p));
                }
            }
            _ => {}
        }
        out.push(path);
    }
    out
}

fn get_mut<'a>(doc: &'a mut Value, path: &[Value]) -> &'a mut Value {
    let mut v = doc;
    for seg in path {
        v = match seg {
            Value::String(k) => &mut v[k.as_str()],
            Value::Number(i) => &mut v[i.as_u64().unwrap() as usize],
            _ => unreachable!(),
        };
    }
    v
}

const NUMBERS: &[f64] = &[
    0.0,
    1.0,
    2.0,
    3.0,
    4.0,
    -1.0,
    0.5,
    255.0,
    256.0,
    65535.0,
    65536.0,
    2147483647.0,
    4294967295.0,
    4294967296.0,
    9007199254740992.0,
    1e19,
    1e39,
    -1e39,
    1e-45,
    1e-40,
    3.5,
    1.5707964,
    5120.0,
    5121.0,
    5122.0,
    5123.0,
    5125.0,
    5126.0,
    34962.0,
];

const URIS: &[&str] = &[
    "b.bin",
    "t.png",
    "big.png",
    "dir",
    "pipe",
    "link",
    "/etc/passwd",
    "/dev/zero",
    "../../../../etc/passwd",
    "%2e%2e/%2e%2e/etc/passwd",
    "file:///etc/passwd",
    "http://localhost/x",
    "data:application/octet-stream;base64,AAAA",
    "data:,x",
    "data:;base64,!!!",
    "",
    ".",
    "fuzz.gltf",
    "%00",
    "%ff%fe",
    "b.bin%",
    "C:\\x",
];

const KEYS: &[&str] = &[
    "count",
    "byteOffset",
    "byteLength",
    "byteStride",
    "bufferView",
    "componentType",
    "buffer",
    "mesh",
    "children",
    "sparse",
    "indices",
    "camera",
    "source",
    "scale",
    "matrix",
    "uri",
    "type",
    "mode",
    "normalized",
];

/// A random JSON value of a kind loaders trip on.
fn random_value(rng: &mut Rng, depth: usize) -> Value {
    match rng.below(if depth > 1 { 5 } else { 8 }) {
        0 | 1 => json!(*rng.pick(NUMBERS)),
        2 => json!(rng.below(12)),
        3 => json!(*rng.pick(URIS)),
        4 => rng
            .pick(&[
                json!(null),
                json!(true),
                json!(false),
                json!("VEC3"),
                json!("SCALAR"),
            ])
            .clone(),
        5 => Value::Array(
            (0..rng.below(5))
                .map(|_| random_value(rng, depth + 1))
                .collect(),
        ),
        6 => {
            let mut m = serde_json::Map::new();
            for _ in 0..rng.below(4) {
                m.insert(rng.pick(KEYS).to_string(), random_value(rng, depth + 1));
            }
            Value::Object(m)
        }
        _ => {
            json!({"count": rng.below(5), "indices": {"bufferView": rng.below(4), "componentType": 5121},
                    "values": {"bufferView": rng.below(4)}})
        }
    }
}

/// One structural change somewhere in `doc`.
pub fn mutate_json(doc: &mut Value, rng: &mut Rng) {
    let all = paths(doc);
    let path = rng.pick(&all).clone();
    let target = get_mut(doc, &path);
    match rng.below(10) {
        // Replace the value, often by one of the same shape.
        0..=3 => {
            *target = match target {
                Value::Number(_) if rng.chance(0.5) => json!(rng.below(8)),
                Value::Number(_) => json!(*rng.pick(NUMBERS)),
                Value::String(s) if s.starts_with("data:") && rng.chance(0.7) => {
                    // Keep most of a buffer, with bytes changed inside it.
                    let mut b = base64_data(s).unwrap_or_default();
                    for _ in 0..1 + rng.below(8) {
                        if !b.is_empty() {
                            let i = rng.below(b.len());
                            b[i] = rng.next() as u8;
                        }
                    }
                    if rng.chance(0.2) {
                        let keep = rng.below(b.len() + 1);
                        b.truncate(keep);
                    }
                    json!(data_uri(&b))
                }
                Value::String(_) => json!(*rng.pick(URIS)),
                // Arrays and objects mostly keep their shape (else it is
                // only a parse error): numbers inside them are reached by
                // other picks.
                Value::Array(a) if rng.chance(0.7) => {
                    let n = a.len();
                    json!((0..n)
                        .map(|_| json!(*rng.pick(NUMBERS)))
                        .collect::<Vec<_>>())
                }
                _ => random_value(rng, 0),
            }
        }
        // Add or remove a key.
        4 | 5 => {
            if let Value::Object(m) = target {
                if rng.chance(0.5) && !m.is_empty() {
                    let k = m.keys().nth(rng.below(m.len())).unwrap().clone();
                    m.remove(&k);
                } else {
                    m.insert(rng.pick(KEYS).to_string(), random_value(rng, 0));
                }
            } else {
                *target = random_value(rng, 0);
            }
        }
        // Duplicate, drop or reorder array elements (node lists become DAGs).
        6 | 7 => {
            if let Value::Array(a) = target {
                if !a.is_empty() {
                    let i = rng.below(a.len());
                    match rng.below(3) {
                        0 => {
                            let v = a[i].clone();
                            a.push(v);
                        }
                        1 => {
                            a.remove(i);
                        }
                        _ => {
                            let j = rng.below(a.len());
                            a.swap(i, j);
                        }
                    }
                }
            } else {
                *target = json!([rng.below(8), rng.below(8)]);
            }
        }
        // Point a child list at random nodes (cycles, deep chains).
        8 => {
            let n = doc["nodes"].as_array().map_or(0, Vec::len);
            let i = rng.below(n);
            let children: Vec<usize> = (0..1 + rng.below(3)).map(|_| rng.below(n)).collect();
            if let Some(node) = doc
                .get_mut("nodes")
                .and_then(|v| v.get_mut(i))
                .and_then(Value::as_object_mut)
            {
                node.insert("children".into(), json!(children));
            }
        }
        // Make an accessor sparse, sometimes without a base view.
        _ => {
            let n = doc["accessors"].as_array().map_or(0, Vec::len);
            let views = doc["bufferViews"].as_array().map_or(1, Vec::len);
            let i = rng.below(n);
            let sparse = json!({"count": 1 + rng.below(4),
                "indices": {"bufferView": rng.below(views), "componentType": *rng.pick(&[5121, 5123, 5125]),
                            "byteOffset": rng.below(3) * 4},
                "values": {"bufferView": rng.below(views)}});
            let drop_view = rng.chance(0.5);
            if let Some(acc) = doc
                .get_mut("accessors")
                .and_then(|v| v.get_mut(i))
                .and_then(Value::as_object_mut)
            {
                acc.insert("sparse".into(), sparse);
                if drop_view {
                    acc.remove("bufferView");
                }
            }
        }
    }
}

/// Byte-level damage: flips, interesting words (lengths in GLB headers),
/// truncation, insertion, duplication.
pub fn mutate_bytes(b: &mut Vec<u8>, rng: &mut Rng) {
    if b.is_empty() {
        b.push(b'{');
        return;
    }
    let i = rng.below(b.len());
    match rng.below(6) {
        0 => b[i] ^= 1 << rng.below(8),
        1 => b[i] = rng.next() as u8,
        2 => {
            let words = [
                0u32,
                1,
                2,
                12,
                20,
                0x7FFF_FFFF,
                0xFFFF_FFFF,
                0x4E4F_534A,
                0x004E_4942,
            ];
            let w = rng.pick(&words).to_le_bytes();
            let at = (i / 4 * 4).min(b.len().saturating_sub(4));
            for (k, x) in w.iter().enumerate() {
                if let Some(slot) = b.get_mut(at + k) {
                    *slot = *x;
                }
            }
        }
        3 => b.truncate(i),
        4 => {
            let n = 1 + rng.below(8);
            let junk: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
            b.splice(i..i, junk);
        }
        _ => {
            let end = (i + 1 + rng.below(64)).min(b.len());
            let chunk = b[i..end].to_vec();
            let at = rng.below(b.len());
            b.splice(at..at, chunk);
        }
    }
}
