//! Images, buffers and samplers backed by gpu-allocator. Each frees itself
//! when dropped; it holds the device (`Arc<Shared>`), so the device outlives it
//! and an error half-way through setup leaks nothing. Nothing here records
//! commands: filling a buffer through a staging copy (`Buffer::with_data`)
//! needs a barrier, so it is in `upload`, above this module and `barrier`.

use super::context::Shared;
use super::Gpu;
use anyhow::{Context as _, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

pub struct Image {
    pub image: vk::Image,
    /// A view of all mips and layers (2D, or 2D array when `layers > 1` or
    /// made by [`Image::array`]).
    pub view: vk::ImageView,
    /// One view per mip level (all layers), for storage writes and attachments.
    pub mip_views: Vec<vk::ImageView>,
    pub format: vk::Format,
    /// Extent of mip 0.
    pub extent: vk::Extent2D,
    pub layers: u32,
    /// Texels along z of mip 0: 1, or the depth of a volume (`Image::volume`).
    pub depth: u32,
    pub mips: u32,
    pub aspect: vk::ImageAspectFlags,
    allocation: Option<Allocation>,
    shared: Arc<Shared>,
}

#[derive(Clone, Copy)]
pub struct ImageDesc<'a> {
    pub name: &'a str,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub layers: u32,
    pub mips: u32,
    pub usage: vk::ImageUsageFlags,
}

impl<'a> ImageDesc<'a> {
    /// A single-layer, single-mip image.
    pub fn flat(
        name: &'a str,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
    ) -> Self {
        Self {
            name,
            format,
            extent,
            layers: 1,
            mips: 1,
            usage,
        }
    }
}

pub fn aspect_of(format: vk::Format) -> vk::ImageAspectFlags {
    match format {
        vk::Format::D32_SFLOAT | vk::Format::D16_UNORM | vk::Format::X8_D24_UNORM_PACK32 => {
            vk::ImageAspectFlags::DEPTH
        }
        vk::Format::S8_UINT => vk::ImageAspectFlags::STENCIL,
        vk::Format::D24_UNORM_S8_UINT | vk::Format::D32_SFLOAT_S8_UINT => {
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL
        }
        _ => vk::ImageAspectFlags::COLOR,
    }
}

/// Bytes per texel of the formats `isr` reads back or budgets memory for.
pub fn texel_bytes(format: vk::Format) -> u64 {
    match format {
        vk::Format::R32G32B32A32_SFLOAT => 16,
        vk::Format::R16G16B16A16_SFLOAT => 8,
        vk::Format::R32_SFLOAT | vk::Format::D32_SFLOAT => 4,
        vk::Format::R8G8B8A8_UNORM | vk::Format::R8G8B8A8_SRGB => 4,
        vk::Format::S8_UINT => 1,
        vk::Format::R32_UINT => 4,
        vk::Format::D32_SFLOAT_S8_UINT => 8,
        vk::Format::D24_UNORM_S8_UINT => 4,
        _ => 16,
    }
}

impl Image {
    pub fn new(gpu: &Gpu, desc: &ImageDesc) -> Result<Self> {
        let view_type = if desc.layers > 1 {
            vk::ImageViewType::TYPE_2D_ARRAY
        } else {
            vk::ImageViewType::TYPE_2D
        };
        Self::with_view_type(gpu, desc, view_type, 1)
    }

    /// An image whose views are 2D arrays whatever its layers: a shader's
    /// `sampler2DArray` takes only such a view, one layer or many.
    pub fn array(gpu: &Gpu, desc: &ImageDesc) -> Result<Self> {
        Self::with_view_type(gpu, desc, vk::ImageViewType::TYPE_2D_ARRAY, 1)
    }

    /// A 3D image of `depth` texels along z (`desc.layers` must be 1), its
    /// views 3D, so that samplers filter across z too (trilinear, and
    /// between mips).
    pub fn volume(gpu: &Gpu, desc: &ImageDesc, depth: u32) -> Result<Self> {
        anyhow::ensure!(desc.layers == 1, "volume {} has one layer", desc.name);
        Self::with_view_type(gpu, desc, vk::ImageViewType::TYPE_3D, depth)
    }

    fn with_view_type(
        gpu: &Gpu,
        desc: &ImageDesc,
        view_type: vk::ImageViewType,
        depth: u32,
    ) -> Result<Self> {
        let aspect = aspect_of(desc.format);
        let volume = view_type == vk::ImageViewType::TYPE_3D;
        let info = vk::ImageCreateInfo::default()
            .image_type(if volume {
                vk::ImageType::TYPE_3D
            } else {
                vk::ImageType::TYPE_2D
            })
            .format(desc.format)
            .extent(vk::Extent3D {
                width: desc.extent.width,
                height: desc.extent.height,
                depth,
            })
            .mip_levels(desc.mips)
            .array_layers(desc.layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let image = unsafe { gpu.device.create_image(&info, None) }
            .with_context(|| format!("creating image {}", desc.name))?;
        // From here on `Drop` frees whatever exists (null handles are skipped).
        let mut out = Self {
            image,
            view: vk::ImageView::null(),
            mip_views: Vec::new(),
            format: desc.format,
            extent: desc.extent,
            layers: desc.layers,
            depth,
            mips: desc.mips,
            aspect,
            allocation: None,
            shared: gpu.shared.clone(),
        };
        let requirements = unsafe { gpu.device.get_image_memory_requirements(image) };
        let allocation = gpu
            .shared
            .allocator
            .lock()
            .unwrap()
            .allocate(&AllocationCreateDesc {
                name: desc.name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .with_context(|| {
                format!(
                    "allocating {} MiB for image {} ({}x{}x{}); try a smaller resolution",
                    requirements.size >> 20,
                    desc.name,
                    desc.extent.width,
                    desc.extent.height,
                    desc.layers * depth
                )
            })?;
        // SAFETY: the memory is bound to this object only, and freed after it.
        let (memory, offset) = (unsafe { allocation.memory() }, allocation.offset());
        out.allocation = Some(allocation);
        unsafe { gpu.device.bind_image_memory(image, memory, offset)? };
        let make_view = |base_mip: u32, mips: u32| {
            let range = vk::ImageSubresourceRange {
                aspect_mask: aspect,
                base_mip_level: base_mip,
                level_count: mips,
                base_array_layer: 0,
                layer_count: desc.layers,
            };
            unsafe {
                gpu.device.create_image_view(
                    &vk::ImageViewCreateInfo::default()
                        .image(image)
                        .view_type(view_type)
                        .format(desc.format)
                        .subresource_range(range),
                    None,
                )
            }
        };
        out.view = make_view(0, desc.mips)?;
        if desc.mips > 1 {
            for m in 0..desc.mips {
                let v = make_view(m, 1)?;
                out.mip_views.push(v);
            }
        } else {
            out.mip_views.push(out.view);
        }
        gpu.name(image, desc.name);
        Ok(out)
    }

    /// Every mip and layer.
    pub fn range(&self) -> vk::ImageSubresourceRange {
        self.mip_range(0, self.mips)
    }

    /// `count` mips from `base`, all layers.
    pub fn mip_range(&self, base: u32, count: u32) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: self.aspect,
            base_mip_level: base,
            level_count: count,
            base_array_layer: 0,
            layer_count: self.layers,
        }
    }

    /// Extent of mip `m`.
    pub fn mip_extent(&self, m: u32) -> vk::Extent2D {
        vk::Extent2D {
            width: (self.extent.width >> m).max(1),
            height: (self.extent.height >> m).max(1),
        }
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        let d = &self.shared.device;
        unsafe {
            for v in &self.mip_views {
                if *v != self.view {
                    d.destroy_image_view(*v, None);
                }
            }
            if self.view != vk::ImageView::null() {
                d.destroy_image_view(self.view, None);
            }
            d.destroy_image(self.image, None);
        }
        if let Some(a) = self.allocation.take() {
            let _ = self.shared.allocator.lock().unwrap().free(a);
        }
    }
}

pub struct Buffer {
    pub buffer: vk::Buffer,
    pub size: u64,
    allocation: Option<Allocation>,
    shared: Arc<Shared>,
}

impl Buffer {
    pub fn new(
        gpu: &Gpu,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self> {
        let size = size.max(4);
        let buffer = unsafe {
            gpu.device.create_buffer(
                &vk::BufferCreateInfo::default().size(size).usage(usage),
                None,
            )
        }
        .with_context(|| format!("creating buffer {name}"))?;
        let mut out = Self {
            buffer,
            size,
            allocation: None,
            shared: gpu.shared.clone(),
        };
        let requirements = unsafe { gpu.device.get_buffer_memory_requirements(buffer) };
        let allocation = gpu
            .shared
            .allocator
            .lock()
            .unwrap()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .with_context(|| format!("allocating {} MiB for buffer {name}", size >> 20))?;
        // SAFETY: the memory is bound to this object only, and freed after it.
        let (memory, offset) = (unsafe { allocation.memory() }, allocation.offset());
        out.allocation = Some(allocation);
        unsafe { gpu.device.bind_buffer_memory(buffer, memory, offset)? };
        gpu.name(buffer, name);
        Ok(out)
    }

    /// Host-visible bytes (CpuToGpu and GpuToCpu buffers only).
    pub fn mapped(&self) -> &[u8] {
        let a = self.allocation.as_ref().expect("buffer was destroyed");
        &a.mapped_slice().expect("buffer is not host-visible")[..self.size as usize]
    }

    pub fn write(&mut self, offset: usize, data: &[u8]) {
        let a = self.allocation.as_mut().expect("buffer was destroyed");
        let slice = a.mapped_slice_mut().expect("buffer is not host-visible");
        slice[offset..offset + data.len()].copy_from_slice(data);
    }

    /// Host-visible bytes as `T`s (CpuToGpu and GpuToCpu buffers only).
    pub fn read_pod<T: bytemuck::Pod>(&self) -> Vec<T> {
        bytemuck::pod_collect_to_vec(self.mapped())
    }

    /// Writes `values` at `offset` bytes (host-visible buffers only).
    pub fn write_pod<T: bytemuck::NoUninit>(&mut self, offset: usize, values: &[T]) {
        self.write(offset, bytemuck::cast_slice(values));
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        unsafe { self.shared.device.destroy_buffer(self.buffer, None) };
        if let Some(a) = self.allocation.take() {
            let _ = self.shared.allocator.lock().unwrap().free(a);
        }
    }
}

/// A sampler that destroys itself when dropped.
pub struct Sampler {
    pub sampler: vk::Sampler,
    shared: Arc<Shared>,
}

impl Sampler {
    pub fn new(gpu: &Gpu, info: &vk::SamplerCreateInfo) -> Result<Self> {
        let sampler =
            unsafe { gpu.device.create_sampler(info, None) }.context("creating a sampler")?;
        Ok(Self {
            sampler,
            shared: gpu.shared.clone(),
        })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        unsafe { self.shared.device.destroy_sampler(self.sampler, None) };
    }
}
