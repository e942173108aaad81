//! The scene on the GPU: what does not change between frames (vertices,
//! indices, materials, textures, the draw list) and the descriptor set the
//! scene passes share (set 1: materials, textures). Where instances are each
//! frame lives in the frame set (`InstanceTransform`s), not here.

use crate::gpu_types::{DrawPush, MaterialGpu};
use crate::scene::{GpuVertex, Scene, Texture};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, DescriptorSet};
use crate::vk::{Buffer, Gpu, Image, ImageDesc};
use anyhow::{bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// One indexed draw of a mesh instance.
pub struct Draw {
    pub first_index: u32,
    pub index_count: u32,
    pub vertex_offset: i32,
    pub double_sided: bool,
    pub push: DrawPush,
}

pub struct SceneGpu {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub materials: Buffer,
    /// At least one (a white texel when the scene has no textures).
    pub textures: Vec<Image>,
    pub draws: Vec<Draw>,
    /// Set 1 of the scene passes: binding 0 materials, 1 textures.
    pub set: DescriptorSet,
    /// `Scene::instances.len()`: the transforms each frame provides.
    pub instance_count: usize,
}

impl SceneGpu {
    pub fn new(gpu: &Gpu, scene: &Scene, texture_sampler: vk::Sampler) -> Result<Self> {
        let limit = gpu
            .limits()
            .max_per_stage_descriptor_sampled_images
            .min(gpu.limits().max_per_stage_descriptor_samplers) as usize;
        if scene.textures.len() > limit.saturating_sub(8) {
            bail!(
                "the scene has {} textures; this device allows {} sampled images per shader stage",
                scene.textures.len(),
                limit
            );
        }
        if scene.textures.len() > 1 && !gpu.features.sampled_image_array_indexing {
            bail!(
                "the scene has {} textures, but this device cannot index texture arrays \
                 (shaderSampledImageArrayDynamicIndexing); use a scene with at most one texture",
                scene.textures.len()
            );
        }
        let mut vertices: Vec<GpuVertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut ranges = Vec::new();
        for mesh in &scene.meshes {
            ranges.push((
                indices.len() as u32,
                mesh.indices.len() as u32,
                vertices.len() as i32,
            ));
            vertices.extend_from_slice(&mesh.vertices);
            indices.extend_from_slice(&mesh.indices);
        }
        let draws = scene
            .instances
            .iter()
            .enumerate()
            .map(|(i, inst)| {
                let mesh = &scene.meshes[inst.mesh];
                let (first_index, index_count, vertex_offset) = ranges[inst.mesh];
                Draw {
                    first_index,
                    index_count,
                    vertex_offset,
                    double_sided: scene.materials[mesh.material].double_sided,
                    push: DrawPush {
                        instance: i as u32,
                        material: mesh.material as u32,
                    },
                }
            })
            .collect();
        let materials: Vec<MaterialGpu> = scene
            .materials
            .iter()
            .map(|m| MaterialGpu {
                base_color: m.base_color.to_array(),
                texture: m.texture.map_or(-1, |t| t as i32),
                ..Default::default()
            })
            .collect();
        let white = Texture {
            name: "white".into(),
            width: 1,
            height: 1,
            rgba8: vec![255; 4],
        };
        let sources: Vec<&Texture> = if scene.textures.is_empty() {
            vec![&white]
        } else {
            scene.textures.iter().collect()
        };
        let textures = sources
            .into_iter()
            .map(|t| upload_texture(gpu, t))
            .collect::<Result<Vec<_>>>()?;
        // Storage too: the visibility grid's voxelization reads the triangles
        // (`voxel_grid`).
        let usage = vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        let vertices = Buffer::with_data(gpu, "vertices", bytemuck::cast_slice(&vertices), usage)?;
        let usage = vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        let indices = Buffer::with_data(gpu, "indices", bytemuck::cast_slice(&indices), usage)?;
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let materials =
            Buffer::with_data(gpu, "materials", bytemuck::cast_slice(&materials), usage)?;
        let views: Vec<vk::ImageView> = textures.iter().map(|t| t.view).collect();
        let set = DescriptorSet::new(
            gpu,
            "scene",
            &[
                Binding::storage("Materials", &materials),
                Binding::sampled_array("textures", &views, texture_sampler),
            ],
        )?;
        Ok(Self {
            vertices,
            indices,
            materials,
            textures,
            draws,
            set,
            instance_count: scene.instances.len(),
        })
    }

    pub fn texture_count(&self) -> usize {
        self.textures.len()
    }
}

fn upload_texture(gpu: &Gpu, t: &Texture) -> Result<Image> {
    let max = gpu.limits().max_image_dimension2_d;
    if t.width > max || t.height > max {
        bail!(
            "texture {} is {}x{}; this device allows at most {max}",
            t.name,
            t.width,
            t.height
        );
    }
    let image = Image::new(
        gpu,
        &ImageDesc::flat(
            &t.name,
            vk::Format::R8G8B8A8_SRGB,
            vk::Extent2D {
                width: t.width,
                height: t.height,
            },
            vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
        ),
    )?;
    let mut staging = Buffer::new(
        gpu,
        "texture staging",
        t.rgba8.len() as u64,
        vk::BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::CpuToGpu,
    )?;
    staging.write(0, &t.rgba8);
    gpu.run_once(|cmd| unsafe {
        barrier::transition(
            gpu,
            cmd,
            &[&image],
            Use::DISCARD_AFTER_READERS,
            Use::TRANSFER_DST,
        );
        let region = vk::BufferImageCopy::default()
            .image_subresource(vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            })
            .image_extent(vk::Extent3D {
                width: t.width,
                height: t.height,
                depth: 1,
            });
        gpu.device.cmd_copy_buffer_to_image(
            cmd,
            staging.buffer,
            image.image,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &[region],
        );
        barrier::transition(gpu, cmd, &[&image], Use::TRANSFER_DST, Use::READ_ONLY);
    })?;
    Ok(image)
}
