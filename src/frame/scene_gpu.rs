//! The scene on the GPU: what does not change between frames (vertices,
//! indices, materials, textures, the draw list) and the descriptor set the
//! scene passes share (set 1: materials, then the texture arrays). Where
//! instances are each frame lives in the frame set (`InstanceTransform`s),
//! not here.

use super::texture_arrays::{self, ArrayPlan, TexturePlan, BINDING_NAMES};
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
    /// Where each texture is: `plan.arrays[i]` is `texture_arrays[i]`.
    pub plan: TexturePlan,
    /// The texture arrays of `plan`, then a 1x1 white one that the bindings
    /// beyond them show (the shaders declare all eight; no material reads
    /// them).
    pub texture_arrays: Vec<Image>,
    pub draws: Vec<Draw>,
    /// Set 1 of the scene passes: binding 0 materials, 1 to 8 the texture
    /// arrays.
    pub set: DescriptorSet,
    /// `Scene::instances.len()`: the transforms each frame provides.
    pub instance_count: usize,
}

impl SceneGpu {
    /// Uploads `scene`, its textures in the arrays of `TexturePlan::new`;
    /// `sampler` filters bilinearly with repeat (`Samplers::texture`).
    pub fn new(gpu: &Gpu, scene: &Scene, sampler: vk::Sampler) -> Result<Self> {
        let plan = TexturePlan::new(&scene.textures)?;
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
            .map(|m| match m.texture {
                Some(t) if t < plan.placements.len() => {
                    let place = plan.placements[t];
                    let (texture_scale, texture_offset) = plan.transform(t);
                    Ok(MaterialGpu {
                        base_color: m.base_color.to_array(),
                        texture_array: place.array as i32,
                        texture_layer: place.layer as i32,
                        texture_scale,
                        texture_offset,
                        ..Default::default()
                    })
                }
                Some(t) => bail!(
                    "material {} names texture {t}; the scene has {}",
                    m.name,
                    plan.placements.len()
                ),
                None => Ok(MaterialGpu {
                    base_color: m.base_color.to_array(),
                    texture_array: -1,
                    ..Default::default()
                }),
            })
            .collect::<Result<_>>()?;
        let fitted = texture_arrays::fitted(&scene.textures);
        let mut texture_arrays = plan
            .arrays
            .iter()
            .enumerate()
            .map(|(i, a)| upload_array(gpu, &format!("texture array {i}"), a, &fitted))
            .collect::<Result<Vec<_>>>()?;
        let white = Texture {
            name: "white".into(),
            width: 1,
            height: 1,
            rgba8: vec![255; 4],
        };
        let unused = ArrayPlan {
            width: 1,
            height: 1,
            textures: vec![0],
            bordered: false,
        };
        texture_arrays.push(upload_array(
            gpu,
            "unused texture arrays",
            &unused,
            &[std::borrow::Cow::Borrowed(&white)],
        )?);
        // Storage too: the visibility grid's voxelization reads the triangles
        // (`voxel_grid`).
        let usage = vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        let vertices = Buffer::with_data(gpu, "vertices", bytemuck::cast_slice(&vertices), usage)?;
        let usage = vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        let indices = Buffer::with_data(gpu, "indices", bytemuck::cast_slice(&indices), usage)?;
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let materials =
            Buffer::with_data(gpu, "materials", bytemuck::cast_slice(&materials), usage)?;
        let mut bindings = vec![Binding::storage("Materials", &materials)];
        let last = texture_arrays.len() - 1;
        for (i, name) in BINDING_NAMES.into_iter().enumerate() {
            let view = texture_arrays[i.min(last)].view;
            bindings.push(Binding::sampled(name, view, sampler));
        }
        let set = DescriptorSet::new(gpu, "scene", &bindings)?;
        Ok(Self {
            vertices,
            indices,
            materials,
            plan,
            texture_arrays,
            draws,
            set,
            instance_count: scene.instances.len(),
        })
    }
}

impl SceneGpu {
    /// The texture arrays the shaders sample (`TEXTURE_ARRAYS` of
    /// `shaders/material.glsl`): the plan's, at least one.
    pub fn texture_arrays_in_use(&self) -> i32 {
        self.plan.arrays.len().max(1) as i32
    }
}

/// One array image holding `a`'s textures (of `textures`), each filling its
/// layer or, in a bordered array, bordered from its top-left corner (the
/// rest of a larger layer is never read).
fn upload_array(
    gpu: &Gpu,
    name: &str,
    a: &ArrayPlan,
    textures: &[std::borrow::Cow<Texture>],
) -> Result<Image> {
    let image = Image::array(
        gpu,
        &ImageDesc {
            name,
            format: vk::Format::R8G8B8A8_SRGB,
            extent: vk::Extent2D {
                width: a.width,
                height: a.height,
            },
            layers: a.textures.len() as u32,
            mips: 1,
            usage: vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
        },
    )?;
    // Each layer's texels and their extent.
    let layers: Vec<(std::borrow::Cow<[u8]>, u32, u32)> = a
        .textures
        .iter()
        .map(|&t| {
            let t = &textures[t];
            match a.bordered {
                true => (
                    texture_arrays::bordered(t).into(),
                    t.width + 2,
                    t.height + 2,
                ),
                false => (t.rgba8.as_slice().into(), t.width, t.height),
            }
        })
        .collect();
    let bytes: u64 = layers.iter().map(|l| l.0.len() as u64).sum();
    let mut staging = Buffer::new(
        gpu,
        "texture staging",
        bytes,
        vk::BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::CpuToGpu,
    )?;
    let mut regions = vec![];
    let mut offset = 0;
    for (layer, (texels, width, height)) in layers.iter().enumerate() {
        staging.write(offset as usize, texels);
        regions.push(
            vk::BufferImageCopy::default()
                .buffer_offset(offset)
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: layer as u32,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D {
                    width: *width,
                    height: *height,
                    depth: 1,
                }),
        );
        offset += texels.len() as u64;
    }
    gpu.run_once(|cmd| unsafe {
        barrier::transition(
            gpu,
            cmd,
            &[&image],
            Use::DISCARD_AFTER_READERS,
            Use::TRANSFER_DST,
        );
        gpu.device.cmd_copy_buffer_to_image(
            cmd,
            staging.buffer,
            image.image,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &regions,
        );
        barrier::transition(gpu, cmd, &[&image], Use::TRANSFER_DST, Use::READ_ONLY);
    })?;
    Ok(image)
}
