//! Specialization constants by name. A shader declares each one once, in
//! GLSL (`layout(constant_id = ID) const TYPE NAME = DEFAULT;`): that line is
//! the one source of its id, type and default. The host sets it by name
//! ([`Spec`]), and every pipeline resolves the names against its shaders'
//! SPIR-V when it is made, as it checks the bindings: a name no shader
//! declares, a constant a shader declares that the host leaves unset, or a
//! value of the wrong type fails there, naming the pipeline, the shader and
//! the constant, instead of rendering with a default or a misread bit pattern.

use super::reflect::{self, SpecKind};
use super::shaders::spirv;
use anyhow::{bail, Result};
use ash::vk;

/// A value for a specialization constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpecValue {
    Bool(bool),
    Int(i32),
    UInt(u32),
    Float(f32),
}

impl SpecValue {
    fn kind(self) -> SpecKind {
        match self {
            SpecValue::Bool(_) => SpecKind::Bool,
            SpecValue::Int(_) => SpecKind::Int,
            SpecValue::UInt(_) => SpecKind::UInt,
            SpecValue::Float(_) => SpecKind::Float,
        }
    }

    /// The 32 bits Vulkan reads (a `VkBool32` for a bool).
    fn bits(self) -> u32 {
        match self {
            SpecValue::Bool(b) => b as u32,
            SpecValue::Int(i) => i as u32,
            SpecValue::UInt(u) => u,
            SpecValue::Float(f) => f.to_bits(),
        }
    }
}

/// The value a pipeline gives the specialization constant its shaders name
/// `name`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    pub name: &'static str,
    pub value: SpecValue,
}

impl Spec {
    pub const fn bool(name: &'static str, value: bool) -> Self {
        Spec {
            name,
            value: SpecValue::Bool(value),
        }
    }

    pub const fn int(name: &'static str, value: i32) -> Self {
        Spec {
            name,
            value: SpecValue::Int(value),
        }
    }

    pub const fn uint(name: &'static str, value: u32) -> Self {
        Spec {
            name,
            value: SpecValue::UInt(value),
        }
    }

    pub const fn float(name: &'static str, value: f32) -> Self {
        Spec {
            name,
            value: SpecValue::Float(value),
        }
    }
}

/// One stage's map entries and data, for `vk::SpecializationInfo`.
#[derive(Default)]
pub(super) struct StageConstants {
    pub entries: Vec<vk::SpecializationMapEntry>,
    pub data: Vec<u8>,
}

/// Checks `given` against the specialization constants that `shaders` (the
/// stages of pipeline `pipeline`) declare, and lays each stage's values out
/// by the ids its SPIR-V gives them.
pub(super) fn resolve(
    pipeline: &str,
    shaders: &[&str],
    given: &[Spec],
) -> Result<Vec<StageConstants>> {
    for (i, s) in given.iter().enumerate() {
        if given[..i].iter().any(|t| t.name == s.name) {
            bail!(
                "pipeline {pipeline} sets specialization constant {} twice",
                s.name
            );
        }
    }
    let mut used = vec![false; given.len()];
    let mut stages = Vec::with_capacity(shaders.len());
    for &shader in shaders {
        let mut stage = StageConstants::default();
        for c in reflect::spec_constants(&spirv(shader)?)? {
            let Some(k) = given.iter().position(|s| s.name == c.name) else {
                bail!(
                    "pipeline {pipeline}: shaders/{shader} declares specialization constant \
                     {} (id {}), which the pipeline does not set",
                    c.name,
                    c.id
                );
            };
            let value = given[k].value;
            if value.kind() != c.kind {
                bail!(
                    "pipeline {pipeline}: shaders/{shader} declares specialization constant {} \
                     as {:?}, but the pipeline gives it {value:?}",
                    c.name,
                    c.kind
                );
            }
            used[k] = true;
            stage.entries.push(vk::SpecializationMapEntry {
                constant_id: c.id,
                offset: stage.data.len() as u32,
                size: 4,
            });
            stage.data.extend_from_slice(&value.bits().to_ne_bytes());
        }
        stages.push(stage);
    }
    if let Some(k) = used.iter().position(|u| !u) {
        bail!(
            "pipeline {pipeline} sets specialization constant {}, which none of its shaders \
             ({}) declares",
            given[k].name,
            shaders.join(", ")
        );
    }
    Ok(stages)
}

/// [`resolve`] for a test: whether `given` sets exactly the constants
/// `shaders` declare, each with its type.
#[doc(hidden)]
pub fn check_specialization(pipeline: &str, shaders: &[&str], given: &[Spec]) -> Result<()> {
    resolve(pipeline, shaders, given).map(|_| ())
}
