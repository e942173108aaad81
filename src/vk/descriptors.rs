//! Descriptor sets written once at creation, and the check of a pipeline's
//! sets against the bindings its shaders declare (`reflect`).

use super::context::Shared;
use super::shaders::spirv;
use super::{reflect, Gpu};
use anyhow::{bail, Context as _, Result};
use ash::vk;
use std::sync::Arc;

/// The resource of one descriptor binding.
#[derive(Clone, Copy)]
pub enum Resource<'a> {
    Uniform(&'a super::Buffer),
    Storage(&'a super::Buffer),
    /// A combined image sampler in `SHADER_READ_ONLY_OPTIMAL`.
    Sampled(vk::ImageView, vk::Sampler),
    /// An array of combined image samplers.
    SampledArray(&'a [vk::ImageView], vk::Sampler),
    /// A storage image in `GENERAL` layout.
    StorageImage(vk::ImageView),
}

/// One descriptor binding, visible to every shader stage of the pipeline. Its
/// `name` is the shader's name for it (the variable, or the block for a block
/// without an instance name); pipelines check it against the SPIR-V.
#[derive(Clone, Copy)]
pub struct Binding<'a> {
    pub name: &'static str,
    pub resource: Resource<'a>,
}

impl<'a> Binding<'a> {
    pub fn uniform(name: &'static str, buffer: &'a super::Buffer) -> Self {
        Self {
            name,
            resource: Resource::Uniform(buffer),
        }
    }
    pub fn storage(name: &'static str, buffer: &'a super::Buffer) -> Self {
        Self {
            name,
            resource: Resource::Storage(buffer),
        }
    }
    pub fn sampled(name: &'static str, view: vk::ImageView, sampler: vk::Sampler) -> Self {
        Self {
            name,
            resource: Resource::Sampled(view, sampler),
        }
    }
    pub fn sampled_array(
        name: &'static str,
        views: &'a [vk::ImageView],
        sampler: vk::Sampler,
    ) -> Self {
        Self {
            name,
            resource: Resource::SampledArray(views, sampler),
        }
    }
    pub fn storage_image(name: &'static str, view: vk::ImageView) -> Self {
        Self {
            name,
            resource: Resource::StorageImage(view),
        }
    }

    fn kind(&self) -> (vk::DescriptorType, u32, reflect::Kind) {
        match self.resource {
            Resource::StorageImage(_) => (
                vk::DescriptorType::STORAGE_IMAGE,
                1,
                reflect::Kind::StorageImage,
            ),
            Resource::Uniform(_) => (
                vk::DescriptorType::UNIFORM_BUFFER,
                1,
                reflect::Kind::UniformBuffer,
            ),
            Resource::Storage(_) => (
                vk::DescriptorType::STORAGE_BUFFER,
                1,
                reflect::Kind::StorageBuffer,
            ),
            Resource::Sampled(..) => (
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                1,
                reflect::Kind::CombinedImageSampler,
            ),
            Resource::SampledArray(views, _) => (
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                views.len() as u32,
                reflect::Kind::CombinedImageSampler,
            ),
        }
    }
}

/// What one binding of a set is, kept for the reflection check.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BindingInfo {
    pub name: &'static str,
    pub kind: reflect::Kind,
}

/// A descriptor set layout, its pool and the one set allocated from it, freed
/// when dropped. Sets are written once at creation: what a pass reads never
/// changes; what changes per frame lives in the frame set (see `frame`).
pub struct DescriptorSet {
    pub layout: vk::DescriptorSetLayout,
    pub pool: vk::DescriptorPool,
    pub set: vk::DescriptorSet,
    /// Binding i's name and kind.
    pub bindings: Vec<BindingInfo>,
    shared: Arc<Shared>,
}

impl DescriptorSet {
    pub fn new(gpu: &Gpu, name: &str, bindings: &[Binding]) -> Result<Self> {
        // One descriptor binds a whole buffer: past the device's range it
        // would read out of bounds, and validation would report it.
        let l = gpu.limits();
        for b in bindings {
            let (buffer, limit, what) = match b.resource {
                Resource::Storage(buf) => {
                    (buf, l.max_storage_buffer_range, "maxStorageBufferRange")
                }
                Resource::Uniform(buf) => {
                    (buf, l.max_uniform_buffer_range, "maxUniformBufferRange")
                }
                _ => continue,
            };
            if buffer.size > limit as u64 {
                bail!(
                    "{name}: buffer {} takes {} MiB, more than {} binds at once ({what}: {} MiB); \
                     choose a smaller resolution, --rsm or --visibility-grid",
                    b.name,
                    buffer.size.div_ceil(1 << 20),
                    gpu.info.name,
                    limit >> 20
                );
            }
        }
        let stages = vk::ShaderStageFlags::ALL_GRAPHICS | vk::ShaderStageFlags::COMPUTE;
        let layout_bindings: Vec<_> = bindings
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let (ty, count, _) = b.kind();
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(ty)
                    .descriptor_count(count)
                    .stage_flags(stages)
            })
            .collect();
        let mut out = Self {
            layout: vk::DescriptorSetLayout::null(),
            pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            bindings: bindings
                .iter()
                .map(|b| BindingInfo {
                    name: b.name,
                    kind: b.kind().2,
                })
                .collect(),
            shared: gpu.shared.clone(),
        };
        out.layout = unsafe {
            gpu.device.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings),
                None,
            )
        }?;
        let sizes: Vec<_> = layout_bindings
            .iter()
            .map(|b| vk::DescriptorPoolSize {
                ty: b.descriptor_type,
                descriptor_count: b.descriptor_count,
            })
            .collect();
        out.pool = unsafe {
            gpu.device.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(1)
                    .pool_sizes(&sizes),
                None,
            )
        }?;
        let layouts = [out.layout];
        out.set = unsafe {
            gpu.device.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(out.pool)
                    .set_layouts(&layouts),
            )
        }
        .with_context(|| format!("allocating descriptor set for {name}"))?[0];

        let buffer_infos: Vec<Vec<vk::DescriptorBufferInfo>> = bindings
            .iter()
            .map(|b| match b.resource {
                Resource::Uniform(buf) | Resource::Storage(buf) => vec![vk::DescriptorBufferInfo {
                    buffer: buf.buffer,
                    offset: 0,
                    range: vk::WHOLE_SIZE,
                }],
                _ => vec![],
            })
            .collect();
        let image_infos: Vec<Vec<vk::DescriptorImageInfo>> = bindings
            .iter()
            .map(|b| {
                let info = |view: vk::ImageView, sampler: vk::Sampler| vk::DescriptorImageInfo {
                    sampler,
                    image_view: view,
                    image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                };
                match b.resource {
                    Resource::StorageImage(view) => vec![vk::DescriptorImageInfo {
                        sampler: vk::Sampler::null(),
                        image_view: view,
                        image_layout: vk::ImageLayout::GENERAL,
                    }],
                    Resource::Sampled(view, sampler) => vec![info(view, sampler)],
                    Resource::SampledArray(views, sampler) => {
                        views.iter().map(|v| info(*v, sampler)).collect()
                    }
                    _ => vec![],
                }
            })
            .collect();
        let writes: Vec<_> = layout_bindings
            .iter()
            .enumerate()
            .map(|(i, lb)| {
                let w = vk::WriteDescriptorSet::default()
                    .dst_set(out.set)
                    .dst_binding(i as u32)
                    .descriptor_type(lb.descriptor_type);
                if buffer_infos[i].is_empty() {
                    w.image_info(&image_infos[i])
                } else {
                    w.buffer_info(&buffer_infos[i])
                }
            })
            .collect();
        unsafe { gpu.device.update_descriptor_sets(&writes, &[]) };
        Ok(out)
    }
}

impl Drop for DescriptorSet {
    fn drop(&mut self) {
        unsafe {
            // Null handles (a set whose creation failed half-way) are ignored.
            self.shared.device.destroy_descriptor_pool(self.pool, None);
            self.shared
                .device
                .destroy_descriptor_set_layout(self.layout, None);
        }
    }
}

/// Checks that `sets` provide, at every (set, binding) that `shaders` declare,
/// a resource of the kind and name the shader expects, and that every binding
/// of the pass's own sets (all but set 0, the frame set, which shaders may use
/// in part) is read by some stage.
pub fn check_bindings(pipeline: &str, shaders: &[&str], sets: &[&[BindingInfo]]) -> Result<()> {
    let mut declared: Vec<(String, reflect::ShaderBinding)> = Vec::new();
    for shader in shaders {
        for b in reflect::bindings(&spirv(shader)?)? {
            declared.push((shader.to_string(), b));
        }
    }
    for (shader, b) in &declared {
        let Some(set) = sets.get(b.set as usize) else {
            bail!(
                "pipeline {pipeline}: {shader} reads set {} binding {} (`{}`), but the pass binds {} set(s)",
                b.set,
                b.binding,
                b.name,
                sets.len()
            );
        };
        match set.get(b.binding as usize) {
            Some(host) if host.name == b.name && host.kind == b.kind => {}
            Some(host) => bail!(
                "pipeline {pipeline}: {shader} expects `{}` ({:?}) at set {} binding {}, but the pass binds `{}` ({:?}) there",
                b.name,
                b.kind,
                b.set,
                b.binding,
                host.name,
                host.kind
            ),
            None => bail!(
                "pipeline {pipeline}: {shader} reads `{}` at set {} binding {}, which the pass does not bind",
                b.name,
                b.set,
                b.binding
            ),
        }
    }
    for (s, set) in sets.iter().enumerate().skip(1) {
        for (i, host) in set.iter().enumerate() {
            let read = declared
                .iter()
                .any(|(_, b)| b.set as usize == s && b.binding as usize == i);
            if !read {
                bail!(
                    "pipeline {pipeline}: the pass binds `{}` at set {s} binding {i}, which none of {shaders:?} reads",
                    host.name
                );
            }
        }
    }
    Ok(())
}
