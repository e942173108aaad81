//! Settings checked against the device before anything is allocated, each
//! failure with a message that says what to change.

use super::targets::target_list;
use crate::settings::{Method, RenderSettings, HISR_MAX_TILE_LEVEL, MAX_LEVELS};
use crate::vk::resources::texel_bytes;
use crate::vk::Gpu;
use anyhow::{bail, Result};
use ash::vk;

/// Checks `s` against `gpu`'s limits and memory.
pub fn check_settings(gpu: &Gpu, s: &RenderSettings) -> Result<()> {
    check_ranges(s)?;
    let l = gpu.limits();
    let max_w = l.max_image_dimension2_d.min(l.max_framebuffer_width);
    let max_h = l.max_image_dimension2_d.min(l.max_framebuffer_height);
    if s.width > max_w || s.height > max_h {
        bail!(
            "resolution {}x{} exceeds what {} can render ({max_w}x{max_h}); choose a smaller --width/--height",
            s.width,
            s.height,
            gpu.info.name
        );
    }
    let r = s.rsm_resolution;
    if r > max_w.min(max_h) {
        bail!(
            "--rsm {r} exceeds this device's image limit of {}",
            max_w.min(max_h)
        );
    }
    let needed = memory_estimate(s);
    let heap = device_local_heap(gpu);
    if heap > 0 && needed > heap / 10 * 9 {
        bail!(
            "resolution {}x{} with --rsm {r} needs about {} MiB of GPU memory; the device has {} MiB. Choose a smaller resolution",
            s.width,
            s.height,
            needed >> 20,
            heap >> 20
        );
    }
    Ok(())
}

/// The largest device-local heap, in bytes (0 if none is reported).
fn device_local_heap(gpu: &Gpu) -> u64 {
    let props = unsafe {
        gpu.instance
            .get_physical_device_memory_properties(gpu.physical)
    };
    props.memory_heaps[..props.memory_heap_count as usize]
        .iter()
        .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
        .map(|h| h.size)
        .max()
        .unwrap_or(0)
}

/// Light views (RSMs) a frame may render: a point light takes six. Each view
/// is a sequence of passes in the frame (and a timing scope each).
pub const MAX_LIGHT_VIEWS: usize = 64;

/// Checks the scene's lights before anything is allocated: their number,
/// and the memory they add (`light_memory_estimate`) on top of the run's.
pub fn check_light_views(
    gpu: &Gpu,
    s: &RenderSettings,
    lights: &[crate::scene::Light],
    views: usize,
    instances: usize,
) -> Result<()> {
    if lights.is_empty() {
        bail!("the scene has no light to render");
    }
    if views > MAX_LIGHT_VIEWS {
        bail!(
            "the scene's {} lights need {views} RSMs (a point light takes six, one per cube face); isr renders at most {MAX_LIGHT_VIEWS} per frame: remove lights",
            lights.len()
        );
    }
    let cube = lights
        .iter()
        .any(|l| l.kind == crate::scene::LightKind::Point);
    let extra = light_memory_estimate(s, views, instances, cube);
    let needed = memory_estimate(s) + extra;
    let heap = device_local_heap(gpu);
    if heap > 0 && needed > heap / 10 * 9 {
        bail!(
            "the scene's {} lights ({views} RSMs) need about {} MiB of GPU memory besides the {} MiB of the run; the device has {} MiB. Remove lights or choose a smaller resolution",
            lights.len(),
            extra >> 20,
            memory_estimate(s) >> 20,
            heap >> 20
        );
    }
    Ok(())
}

/// Bytes that lights add to `memory_estimate`. The views of a frame run one
/// after another and reuse the one RSM, its quadtree and the method's
/// buffers; what grows with them is a frame set per view and frame in flight
/// (uniforms and instance transforms, host-visible), with more than one view
/// the two full-resolution sums of `light-sum`, and with point lights (`cube`)
/// the six-layer cube RSM they share.
pub fn light_memory_estimate(
    s: &RenderSettings,
    views: usize,
    instances: usize,
    cube: bool,
) -> u64 {
    let frame_set = std::mem::size_of::<crate::gpu_types::FrameUniforms>() as u64
        + instances.max(1) as u64
            * std::mem::size_of::<crate::gpu_types::InstanceTransform>() as u64;
    let sets = views as u64 * super::FRAMES_IN_FLIGHT as u64 * frame_set;
    let sums = if views > 1 {
        2 * s.width as u64 * s.height as u64 * texel_bytes(super::targets::HDR_FORMAT)
    } else {
        0
    };
    let cube = if cube {
        crate::passes::rsm_cube::cube_bytes(s.rsm_resolution)
    } else {
        0
    };
    sets + sums + cube
}

/// Bytes of GPU memory the targets, readback buffers and the method's
/// hierarchy take.
pub fn memory_estimate(s: &RenderSettings) -> u64 {
    let pixels = s.width as u64 * s.height as u64;
    let targets: u64 = target_list()
        .iter()
        .map(|t| {
            // RSM color images carry the quadtree: a mip chain, 4/3 the texels.
            let texels = if t.at_rsm_resolution {
                (s.rsm_resolution as u64).pow(2) * 4 / 3
            } else {
                pixels
            };
            texels * texel_bytes(t.format)
        })
        .sum();
    // Readback buffers for the largest layers.
    let readback = pixels * 16 * 2;
    targets
        + readback
        + if s.method.uses_multires() {
            multires_bytes(s)
        } else {
            0
        }
        + if s.method == Method::Hisr {
            let node = std::mem::size_of::<crate::gpu_types::LightPatch>() as u64;
            crate::methods::hisr::packed_nodes(s) * node + crate::methods::hisr::cut_bytes(s)
        } else {
            0
        }
}

/// GPU memory of the multiresolution buffer: (L + 1) layers of illumination
/// (RGBA32F), evaluation counts (R32F) and stencil, plus five geometry mip
/// chains (four RGBA32F, one R32UI).
fn multires_bytes(s: &RenderSettings) -> u64 {
    let pixels = s.width as u64 * s.height as u64;
    let layers = s.levels().min(MAX_LEVELS) as u64 + 1;
    layers * pixels * (16 + 4 + 4) + pixels * 4 / 3 * (4 * 16 + 4)
}

/// The checks that need no device: sizes, powers of two, ranges.
pub fn check_ranges(s: &RenderSettings) -> Result<()> {
    if s.width == 0 || s.height == 0 {
        bail!(
            "resolution {}x{} is empty: width and height must be at least 1",
            s.width,
            s.height
        );
    }
    let r = s.rsm_resolution;
    if !r.is_power_of_two() || r < 16 {
        bail!("--rsm {r}: the RSM resolution must be a power of two of at least 16 (it is the root of a quadtree)");
    }
    if !(s.exposure.is_finite() && s.exposure >= 0.0) {
        bail!("--exposure must be a finite non-negative number");
    }
    if !(s.splat_threshold.is_finite() && s.splat_threshold >= 0.0) {
        bail!("--splat-threshold must be a finite non-negative irradiance (W/m^2)");
    }
    if s.method == Method::MultiresSplat && !s.multires.stencil {
        bail!("--stencil off measures the stenciled gathers; multires-splat always splats through the stencil");
    }
    if s.method.uses_multires() && (s.width < 2 || s.height < 2) {
        bail!(
            "resolution {}x{}: method {} needs at least 2x2 pixels (its multiresolution buffer's \
             coarsest level halves the image at least once); use a larger --width/--height, or a \
             method without that buffer (rsm-gather, rsm-splat, reference)",
            s.width,
            s.height,
            s.method.name()
        );
    }
    if !s.method.uses_regular_vpls() {
        return Ok(());
    }
    let side = (s.vpls as f64).sqrt() as u32;
    if s.vpls == 0 || side * side != s.vpls || !side.is_power_of_two() {
        bail!(
            "--vpls {}: the number of regular VPLs must be a power of 4 (1, 4, 16, ..., 4096, ...)",
            s.vpls
        );
    }
    if side > r {
        bail!(
            "--vpls {} needs more RSM texels than --rsm {r} has ({} at most)",
            s.vpls,
            r as u64 * r as u64
        );
    }
    let levels = s.levels();
    if s.method.uses_multires()
        && (levels == 0
            || levels >= MAX_LEVELS
            || s.width >> levels == 0
            || s.height >> levels == 0)
    {
        let what = if s.multires.levels.is_some() {
            format!("--levels {levels}")
        } else {
            format!(
                "the default --levels ({levels}) for {}x{}",
                s.width, s.height
            )
        };
        bail!(
            "{what}: the coarsest level must be at least 1 and its texels ({0}x{0} pixels) no larger than the image; \
             choose a larger --width/--height or a smaller --levels",
            1u64 << levels.min(63)
        );
    }
    let m = &s.multires;
    let lt = &s.light_tree;
    if s.method == Method::Isr && (!lt.isr_base.is_power_of_two() || lt.isr_base > r) {
        bail!(
            "--isr-base {}: the base must be a power of 2 no larger than --rsm {r}",
            lt.isr_base
        );
    }
    let top = r.ilog2();
    let max_depth = s.hisr_max_depth();
    if s.method == Method::Hisr && (max_depth > top || lt.start_level > max_depth) {
        bail!(
            "--start-level {} and --max-depth {max_depth} must satisfy start <= max <= log2(--rsm) = {top}",
            lt.start_level
        );
    }
    if lt.hisr_tile_level > HISR_MAX_TILE_LEVEL {
        bail!(
            "--hisr-tile-level {}: tiles of more than 2^{HISR_MAX_TILE_LEVEL} pixels a side share too little; use 0 (off) to {HISR_MAX_TILE_LEVEL}",
            lt.hisr_tile_level
        );
    }
    if !(lt.tau > 0.0 && lt.tau < 1.0) {
        bail!(
            "--tau {}: tau is a fraction of the light's intensity, strictly between 0 and 1",
            lt.tau
        );
    }
    if !(lt.depth_threshold.is_finite()
        && lt.depth_threshold >= 0.0
        && (0.0..=180.0).contains(&lt.normal_threshold_deg))
    {
        bail!("--light-depth-threshold must be >= 0 and --light-normal-threshold within 0..=180 degrees");
    }
    let depth_ok = m.depth_threshold.is_finite() && m.depth_threshold >= 0.0;
    let normal_ok =
        m.normal_threshold_deg.is_finite() && (0.0..=180.0).contains(&m.normal_threshold_deg);
    if !(depth_ok && normal_ok) {
        bail!("--depth-threshold must be >= 0 and --normal-threshold within 0..=180 degrees");
    }
    Ok(())
}
