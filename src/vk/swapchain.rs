//! A window's surface and swapchain, for the viewer: owners that free
//! themselves (the surface before the instance: both hold `Shared`), the
//! swapchain's images and views, and a presentation semaphore per image.

use super::context::Shared;
use super::Gpu;
use anyhow::{bail, Context as _, Result};
use ash::vk;
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};
use std::sync::Arc;

/// A `VkSurfaceKHR` for one window; the window must outlive it.
pub struct Surface {
    pub loader: ash::khr::surface::Instance,
    pub surface: vk::SurfaceKHR,
    _shared: Arc<Shared>,
}

impl Surface {
    pub fn new(gpu: &Gpu, display: RawDisplayHandle, window: RawWindowHandle) -> Result<Self> {
        let surface =
            unsafe { ash_window::create_surface(&gpu.entry, &gpu.instance, display, window, None) }
                .context("creating a Vulkan surface for the window")?;
        let loader = ash::khr::surface::Instance::new(&gpu.entry, &gpu.instance);
        let out = Self {
            loader,
            surface,
            _shared: gpu.shared.clone(),
        };
        let supported = unsafe {
            out.loader
                .get_physical_device_surface_support(gpu.physical, gpu.queue_family, surface)
        }?;
        if !supported {
            bail!(
                "{} cannot present to this window from its graphics queue; \
                 pick another device with --device (`isr devices` lists them)",
                gpu.info.name
            );
        }
        Ok(out)
    }
}

impl Drop for Surface {
    fn drop(&mut self) {
        unsafe { self.loader.destroy_surface(self.surface, None) };
    }
}

/// Usage every swapchain image needs: drawn into by the present and overlay
/// passes, copied from for screenshots.
const USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::COLOR_ATTACHMENT.as_raw() | vk::ImageUsageFlags::TRANSFER_SRC.as_raw(),
);

pub struct Swapchain {
    pub loader: ash::khr::swapchain::Device,
    pub swapchain: vk::SwapchainKHR,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub images: Vec<vk::Image>,
    pub views: Vec<vk::ImageView>,
    /// Signalled by the frame that draws image i, waited on by its presentation.
    pub rendered: Vec<vk::Semaphore>,
    shared: Arc<Shared>,
}

/// The surface format: 8-bit BGRA or RGBA, UNORM preferred (the renderer's
/// display image already holds sRGB-encoded values), else sRGB.
fn pick_format(formats: &[vk::SurfaceFormatKHR]) -> Option<vk::SurfaceFormatKHR> {
    let rank = |f: &vk::SurfaceFormatKHR| match f.format {
        vk::Format::B8G8R8A8_UNORM | vk::Format::R8G8B8A8_UNORM => Some(0),
        vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB => Some(1),
        _ => None,
    };
    formats
        .iter()
        .filter(|f| f.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
        .filter_map(|f| rank(f).map(|r| (r, *f)))
        .min_by_key(|(r, _)| *r)
        .map(|(_, f)| f)
}

/// Whether the swapchain's format encodes sRGB itself (shaders then write linear values).
pub fn is_srgb(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB
    )
}

impl Swapchain {
    /// A swapchain for `surface` of about `size` pixels (the surface's
    /// current extent wins when it has one), replacing `old` if given.
    /// `None` when the window has no area (minimised).
    pub fn new(
        gpu: &Gpu,
        surface: &Surface,
        size: (u32, u32),
        old: Option<&Swapchain>,
    ) -> Result<Option<Self>> {
        let (sl, s) = (&surface.loader, surface.surface);
        let caps = unsafe { sl.get_physical_device_surface_capabilities(gpu.physical, s) }?;
        let formats = unsafe { sl.get_physical_device_surface_formats(gpu.physical, s) }?;
        let modes = unsafe { sl.get_physical_device_surface_present_modes(gpu.physical, s) }?;
        let Some(format) = pick_format(&formats) else {
            bail!("the window surface offers no 8-bit RGBA/BGRA format: {formats:?}");
        };
        if !caps.supported_usage_flags.contains(USAGE) {
            bail!(
                "the window surface does not support color attachment and transfer-source images ({:?})",
                caps.supported_usage_flags
            );
        }
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: size
                    .0
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: size
                    .1
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        if extent.width == 0 || extent.height == 0 {
            return Ok(None);
        }
        // Mailbox when there is one (no tearing, no waiting for vblank);
        // FIFO is always there.
        let mode = if modes.contains(&vk::PresentModeKHR::MAILBOX) {
            vk::PresentModeKHR::MAILBOX
        } else {
            vk::PresentModeKHR::FIFO
        };
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let composite = if caps
            .supported_composite_alpha
            .contains(vk::CompositeAlphaFlagsKHR::OPAQUE)
        {
            vk::CompositeAlphaFlagsKHR::OPAQUE
        } else {
            vk::CompositeAlphaFlagsKHR::INHERIT
        };
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(s)
            .min_image_count(count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(USAGE)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(composite)
            .present_mode(mode)
            .clipped(true)
            .old_swapchain(old.map_or(vk::SwapchainKHR::null(), |o| o.swapchain));
        let loader = ash::khr::swapchain::Device::new(&gpu.instance, &gpu.device);
        let swapchain =
            unsafe { loader.create_swapchain(&info, None) }.context("creating the swapchain")?;
        // From here on `out` frees what was made if a later step fails.
        let mut out = Self {
            loader,
            swapchain,
            format: format.format,
            extent,
            images: Vec::new(),
            views: Vec::new(),
            rendered: Vec::new(),
            shared: gpu.shared.clone(),
        };
        out.images = unsafe { out.loader.get_swapchain_images(swapchain) }?;
        for (i, &image) in out.images.clone().iter().enumerate() {
            let view = unsafe {
                gpu.device.create_image_view(
                    &vk::ImageViewCreateInfo::default()
                        .image(image)
                        .view_type(vk::ImageViewType::TYPE_2D)
                        .format(format.format)
                        .subresource_range(COLOR_RANGE),
                    None,
                )
            }?;
            out.views.push(view);
            let semaphore = unsafe {
                gpu.device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            }?;
            out.rendered.push(semaphore);
            gpu.name(image, &format!("swapchain image {i}"));
        }
        Ok(Some(out))
    }
}

pub const COLOR_RANGE: vk::ImageSubresourceRange = vk::ImageSubresourceRange {
    aspect_mask: vk::ImageAspectFlags::COLOR,
    base_mip_level: 0,
    level_count: 1,
    base_array_layer: 0,
    layer_count: 1,
};

impl Drop for Swapchain {
    fn drop(&mut self) {
        let d = &self.shared.device;
        unsafe {
            // Presentation may still read the images and wait on the semaphores.
            let _ = d.device_wait_idle();
            for &v in &self.views {
                d.destroy_image_view(v, None);
            }
            for &s in &self.rendered {
                d.destroy_semaphore(s, None);
            }
            self.loader.destroy_swapchain(self.swapchain, None);
        }
    }
}

/// Binary semaphores (a swapchain image's acquisition, one per frame in
/// flight), freed when dropped.
pub struct Semaphores {
    pub list: Vec<vk::Semaphore>,
    shared: Arc<Shared>,
}

impl Semaphores {
    pub fn new(gpu: &Gpu, n: usize) -> Result<Self> {
        // Made into their owner, which frees them if a later one fails.
        let mut out = Self {
            list: Vec::new(),
            shared: gpu.shared.clone(),
        };
        for _ in 0..n {
            let s = unsafe {
                gpu.device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            }?;
            out.list.push(s);
        }
        Ok(out)
    }
}

impl Drop for Semaphores {
    fn drop(&mut self) {
        unsafe {
            let _ = self.shared.device.device_wait_idle();
            for &s in &self.list {
                self.shared.device.destroy_semaphore(s, None);
            }
        }
    }
}
