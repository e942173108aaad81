//! The descriptor bindings a compiled shader declares, read from its SPIR-V,
//! so that every pipeline checks at creation that the host binds, at each
//! (set, binding), a resource of the kind and name the shader expects. A
//! swapped pair of bindings of the same type fails here instead of rendering
//! the wrong image.

use anyhow::{bail, Result};
use std::collections::HashMap;

/// What a descriptor binding holds, as far as a pipeline layout cares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    UniformBuffer,
    StorageBuffer,
    CombinedImageSampler,
    StorageImage,
    /// Anything else (separate images or samplers): `isr` binds none.
    Other,
}

/// One descriptor variable of a shader.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShaderBinding {
    pub set: u32,
    pub binding: u32,
    /// The variable's name, or its block's type name for a block without an
    /// instance name (`uniform Frame { ... };` is `Frame`).
    pub name: String,
    pub kind: Kind,
}

const OP_NAME: u32 = 5;
const OP_DECORATE: u32 = 71;
const OP_TYPE_IMAGE: u32 = 25;
const OP_TYPE_SAMPLED_IMAGE: u32 = 27;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
const OP_TYPE_POINTER: u32 = 32;
const OP_VARIABLE: u32 = 59;
const DECORATION_BLOCK: u32 = 2;
const DECORATION_BUFFER_BLOCK: u32 = 3;
const DECORATION_BINDING: u32 = 33;
const DECORATION_DESCRIPTOR_SET: u32 = 34;
const STORAGE_UNIFORM_CONSTANT: u32 = 0;
const STORAGE_UNIFORM: u32 = 2;
const STORAGE_STORAGE_BUFFER: u32 = 12;

/// The nul-terminated string that starts at `words` (SPIR-V literal strings).
pub fn string_at(words: &[u32]) -> String {
    let bytes: Vec<u8> = words
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .take_while(|&b| b != 0)
        .collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

/// Every descriptor variable `words` (a SPIR-V module) declares, by (set, binding).
pub fn bindings(words: &[u32]) -> Result<Vec<ShaderBinding>> {
    if words.len() < 5 || words[0] != 0x0723_0203 {
        bail!("not a SPIR-V module");
    }
    let mut names: HashMap<u32, String> = HashMap::new();
    let mut decorations: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
    // Type id -> the instruction's operands (after the result id).
    let mut types: HashMap<u32, (u32, Vec<u32>)> = HashMap::new();
    let mut variables: Vec<(u32, u32, u32)> = Vec::new();
    let mut i = 5;
    while i < words.len() {
        let (op, count) = (words[i] & 0xffff, (words[i] >> 16) as usize);
        if count == 0 || i + count > words.len() {
            bail!("truncated SPIR-V instruction at word {i}");
        }
        let ins = &words[i..i + count];
        match op {
            OP_NAME if count >= 3 => {
                names.insert(ins[1], string_at(&ins[2..]));
            }
            OP_DECORATE if count >= 3 => {
                let value = ins.get(3).copied().unwrap_or(0);
                decorations.entry(ins[1]).or_default().push((ins[2], value));
            }
            OP_TYPE_IMAGE
            | OP_TYPE_SAMPLED_IMAGE
            | OP_TYPE_ARRAY
            | OP_TYPE_RUNTIME_ARRAY
            | OP_TYPE_POINTER
                if count >= 3 =>
            {
                types.insert(ins[1], (op, ins[2..].to_vec()));
            }
            OP_VARIABLE if count >= 4 => variables.push((ins[1], ins[2], ins[3])),
            _ => {}
        }
        i += count;
    }
    let decoration = |id: u32, which: u32| {
        decorations
            .get(&id)
            .and_then(|d| d.iter().find(|(k, _)| *k == which).map(|(_, v)| *v))
    };
    let has = |id: u32, which: u32| decoration(id, which).is_some();
    let mut out = Vec::new();
    for (pointer_type, id, storage) in variables {
        let (Some(set), Some(binding)) = (
            decoration(id, DECORATION_DESCRIPTOR_SET),
            decoration(id, DECORATION_BINDING),
        ) else {
            continue;
        };
        // Pointer -> pointee, through arrays to the element type.
        let mut ty = match types.get(&pointer_type) {
            Some((OP_TYPE_POINTER, ops)) if ops.len() >= 2 => ops[1],
            _ => bail!("descriptor variable {id} is not a pointer"),
        };
        while let Some((OP_TYPE_ARRAY | OP_TYPE_RUNTIME_ARRAY, ops)) = types.get(&ty) {
            ty = ops[0];
        }
        let kind = match storage {
            STORAGE_UNIFORM if has(ty, DECORATION_BUFFER_BLOCK) => Kind::StorageBuffer,
            STORAGE_UNIFORM if has(ty, DECORATION_BLOCK) => Kind::UniformBuffer,
            STORAGE_STORAGE_BUFFER => Kind::StorageBuffer,
            STORAGE_UNIFORM_CONSTANT => match types.get(&ty) {
                Some((OP_TYPE_SAMPLED_IMAGE, _)) => Kind::CombinedImageSampler,
                // Operand 5 after the result id is `Sampled`: 2 = storage image.
                Some((OP_TYPE_IMAGE, ops)) if ops.get(5) == Some(&2) => Kind::StorageImage,
                _ => Kind::Other,
            },
            _ => Kind::Other,
        };
        let name = match names.get(&id).filter(|n| !n.is_empty()) {
            Some(n) => n.clone(),
            None => names.get(&ty).cloned().unwrap_or_default(),
        };
        out.push(ShaderBinding {
            set,
            binding,
            name,
            kind,
        });
    }
    out.sort_by_key(|b| (b.set, b.binding));
    Ok(out)
}

/// The type of a specialization constant, as its SPIR-V declares it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecKind {
    Bool,
    Int,
    UInt,
    Float,
}

/// One specialization constant of a shader: `layout(constant_id = ID) const
/// TYPE NAME = ...;`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShaderSpecConstant {
    pub id: u32,
    pub name: String,
    pub kind: SpecKind,
}

const OP_TYPE_BOOL: u32 = 20;
const OP_TYPE_INT: u32 = 21;
const OP_TYPE_FLOAT: u32 = 22;
const OP_SPEC_CONSTANT_TRUE: u32 = 48;
const OP_SPEC_CONSTANT_FALSE: u32 = 49;
const OP_SPEC_CONSTANT: u32 = 50;
const DECORATION_SPEC_ID: u32 = 1;

/// Every scalar specialization constant `words` (a SPIR-V module) declares,
/// by id: its name and type, so that hosts set them by name and a wrong type
/// fails when the pipeline is made.
pub fn spec_constants(words: &[u32]) -> Result<Vec<ShaderSpecConstant>> {
    if words.len() < 5 || words[0] != 0x0723_0203 {
        bail!("not a SPIR-V module");
    }
    let mut names: HashMap<u32, String> = HashMap::new();
    let mut spec_ids: HashMap<u32, u32> = HashMap::new();
    let mut scalar_types: HashMap<u32, SpecKind> = HashMap::new();
    // (result id, result type id or None for a bool).
    let mut constants: Vec<(u32, Option<u32>)> = Vec::new();
    let mut i = 5;
    while i < words.len() {
        let (op, count) = (words[i] & 0xffff, (words[i] >> 16) as usize);
        if count == 0 || i + count > words.len() {
            bail!("truncated SPIR-V instruction at word {i}");
        }
        let ins = &words[i..i + count];
        match op {
            OP_NAME if count >= 3 => {
                names.insert(ins[1], string_at(&ins[2..]));
            }
            OP_DECORATE if count >= 4 && ins[2] == DECORATION_SPEC_ID => {
                spec_ids.insert(ins[1], ins[3]);
            }
            OP_TYPE_BOOL if count >= 2 => {
                scalar_types.insert(ins[1], SpecKind::Bool);
            }
            OP_TYPE_INT if count >= 4 => {
                let kind = if ins[3] == 1 {
                    SpecKind::Int
                } else {
                    SpecKind::UInt
                };
                scalar_types.insert(ins[1], kind);
            }
            OP_TYPE_FLOAT if count >= 3 => {
                scalar_types.insert(ins[1], SpecKind::Float);
            }
            OP_SPEC_CONSTANT_TRUE | OP_SPEC_CONSTANT_FALSE if count >= 3 => {
                constants.push((ins[2], None));
            }
            OP_SPEC_CONSTANT if count >= 4 => constants.push((ins[2], Some(ins[1]))),
            _ => {}
        }
        i += count;
    }
    let mut out = Vec::new();
    for (id, ty) in constants {
        // Constants folded from others (`OpSpecConstantOp`) have no SpecId.
        let Some(&spec_id) = spec_ids.get(&id) else {
            continue;
        };
        let kind = match ty {
            None => SpecKind::Bool,
            Some(t) => match scalar_types.get(&t) {
                Some(k) => *k,
                None => bail!("specialization constant {spec_id} has a type that is not a scalar"),
            },
        };
        out.push(ShaderSpecConstant {
            id: spec_id,
            name: names.get(&id).cloned().unwrap_or_default(),
            kind,
        });
    }
    out.sort_by_key(|c| c.id);
    Ok(out)
}
