//! Settings checked against the device before anything is allocated, each
//! failure with a message that says what to change. The method's own
//! parameters are checked by the method (`methods::check`); what its
//! resources and the point lights' cube RSM take is passed in by the
//! renderer, which knows them ([`AddedMemory`]).

use super::targets::target_list;
use crate::settings::RenderSettings;
use crate::vk::resources::texel_bytes;
use crate::vk::Gpu;
use anyhow::{bail, Result};
use ash::vk;

/// GPU memory that the layers above `frame` add to the targets', each
/// estimated by the module that allocates it.
#[derive(Clone, Copy, Debug, Default)]
pub struct AddedMemory {
    /// The method's resources (`methods::Descriptor::memory`).
    pub method: u64,
    /// The point lights' six-layer cube RSM, when the scene has one
    /// (`passes::rsm_cube::cube_bytes`).
    pub cube_rsm: u64,
    /// The scene's texture arrays (`texture_arrays::TexturePlan::bytes`).
    pub textures: u64,
}

/// Checks `s` against `gpu`'s limits and memory; `method_bytes` is what the
/// method's resources take.
pub fn check_settings(gpu: &Gpu, s: &RenderSettings, method_bytes: u64) -> Result<()> {
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
    // The finest-grained dispatch, hisr-visibility's, has a workgroup per
    // tile of 2 pixels a side at --hisr-tile-level 1.
    let groups = l.max_compute_work_group_count;
    if s.width.div_ceil(2) > groups[0] || s.height.div_ceil(2) > groups[1] {
        bail!(
            "resolution {}x{} needs more compute workgroups a side than {} dispatches ({}x{}); \
             choose a smaller --width/--height",
            s.width,
            s.height,
            gpu.info.name,
            groups[0],
            groups[1]
        );
    }
    let r = s.rsm_resolution;
    if r > max_w.min(max_h) {
        bail!(
            "--rsm {r} exceeds this device's image limit of {}",
            max_w.min(max_h)
        );
    }
    let shadow = s.shadow_size();
    if shadow > max_w.min(max_h) {
        bail!(
            "--shadow {shadow} exceeds this device's image limit of {}",
            max_w.min(max_h)
        );
    }
    let needed = memory_estimate(s, method_bytes);
    within_memory_share(
        &format!(
            "resolution {}x{} with --rsm {r} needs about {} MiB of GPU memory",
            s.width,
            s.height,
            needed >> 20
        ),
        needed,
        device_local_heap(gpu),
        "Choose a smaller resolution",
    )
}

/// The share of the largest device-local heap a run may plan to use, in
/// percent: the rest is left to the driver, the window system and other
/// programs, and to what the estimates leave out.
pub const MEMORY_SHARE_PERCENT: u64 = 90;

/// The bytes of a `heap` a run may use ([`MEMORY_SHARE_PERCENT`]).
pub fn usable_memory(heap: u64) -> u64 {
    heap / 100 * MEMORY_SHARE_PERCENT
}

/// Refuses `needed` bytes if they pass the usable share of `heap` (0: not
/// reported, nothing is refused), saying the rule and the numbers: `what`
/// starts the message, `advice` ends it.
fn within_memory_share(what: &str, needed: u64, heap: u64, advice: &str) -> Result<()> {
    let usable = usable_memory(heap);
    if heap > 0 && needed > usable {
        bail!(
            "{what}; isr plans to use at most {} MiB, {MEMORY_SHARE_PERCENT}% of the device's {} MiB \
             heap. {advice}",
            usable >> 20,
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
    (views, instances): (usize, usize),
    added: AddedMemory,
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
    let extra = light_memory_estimate(s, views, instances, added.cube_rsm);
    let run = memory_estimate(s, added.method) + added.textures;
    within_memory_share(
        &light_views_need(lights.len(), views, extra, run),
        run + extra,
        device_local_heap(gpu),
        "Remove lights or choose a smaller resolution",
    )
}

/// Checks that the scene's texture arrays (`textures` bytes) fit beside the
/// run's targets and the method's `method_bytes`.
pub fn check_textures(
    gpu: &Gpu,
    s: &RenderSettings,
    method_bytes: u64,
    textures: u64,
) -> Result<()> {
    let run = memory_estimate(s, method_bytes);
    within_memory_share(
        &textures_need(textures, run),
        run + textures,
        device_local_heap(gpu),
        "Use a scene with smaller textures, or choose a smaller resolution",
    )
}

/// The start of [`check_textures`]' refusal.
fn textures_need(textures: u64, run: u64) -> String {
    format!(
        "the scene's textures need about {} MiB of GPU memory besides the {} MiB of the run, {} \
         MiB in all",
        textures >> 20,
        run >> 20,
        (textures + run) >> 20
    )
}

/// The start of [`check_light_views`]' refusal.
fn light_views_need(lights: usize, views: usize, extra: u64, run: u64) -> String {
    format!(
        "the scene's {lights} lights ({views} RSMs) need about {} MiB of GPU memory besides the \
         {} MiB of the run, {} MiB in all",
        extra >> 20,
        run >> 20,
        (extra + run) >> 20
    )
}

/// Bytes that lights add to `memory_estimate`. The views of a frame run one
/// after another and reuse the one RSM, its quadtree and the method's
/// buffers; what grows with them is a frame set per view and frame in flight
/// (uniforms and instance transforms, host-visible), with more than one view
/// the two full-resolution sums of `light-sum`, and with point lights
/// the six-layer cube RSM they share (`cube_bytes`, 0 without).
pub fn light_memory_estimate(
    s: &RenderSettings,
    views: usize,
    instances: usize,
    cube_bytes: u64,
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
    sets + sums + cube_bytes
}

/// Bytes of GPU memory the targets and readback buffers take, plus the
/// method's `method_bytes`.
pub fn memory_estimate(s: &RenderSettings, method_bytes: u64) -> u64 {
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
    // The direct light's shadow map (`passes::shadow`): depth only.
    let shadow = (s.shadow_size() as u64).pow(2) * texel_bytes(super::targets::DEPTH_FORMAT);
    // Readback buffers for the largest layers.
    let readback = pixels * 16 * 2;
    targets + shadow + readback + method_bytes
}

/// The checks of the settings every run shares that need no device: sizes,
/// the RSM's power of two, the exposure.
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
    let shadow = s.shadow_resolution;
    if shadow != 0 && (!shadow.is_power_of_two() || shadow < 16) {
        bail!("--shadow {shadow}: the shadow map resolution must be a power of two of at least 16");
    }
    if !(s.exposure.is_finite() && s.exposure >= 0.0) {
        bail!(
            "--exposure {}: the exposure must be a finite non-negative number",
            s.exposure
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const MIB: u64 = 1 << 20;

    /// Issue 29, item 11: 1858 MiB of a 2048 MiB heap was refused with only
    /// those two numbers; the message states the share that is allowed.
    #[test]
    fn a_memory_refusal_states_the_rule_and_agrees_with_it() {
        let heap = 2048 * MIB;
        assert_eq!(usable_memory(heap) >> 20, 1843);
        let e = within_memory_share("it needs about 1858 MiB", 1858 * MIB, heap, "Choose less")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "it needs about 1858 MiB; isr plans to use at most 1843 MiB, 90% of the device's \
             2048 MiB heap. Choose less"
        );
        within_memory_share("", usable_memory(heap), heap, "").unwrap();
        let what = textures_need(900 * MIB, 1000 * MIB);
        assert_eq!(
            what,
            "the scene's textures need about 900 MiB of GPU memory besides the 1000 MiB of the \
             run, 1900 MiB in all"
        );
        let e = within_memory_share(&what, 1900 * MIB, heap, "Use smaller textures")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("1900 MiB in all; isr plans to use at most 1843 MiB"),
            "{e}"
        );
        within_memory_share("", u64::MAX, 0, "").unwrap();
        let what = light_views_need(3, 8, 400 * MIB, 1500 * MIB);
        assert_eq!(
            what,
            "the scene's 3 lights (8 RSMs) need about 400 MiB of GPU memory besides the 1500 MiB \
             of the run, 1900 MiB in all"
        );
        let e = within_memory_share(&what, 1900 * MIB, heap, "Remove lights")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("1900 MiB in all; isr plans to use at most 1843 MiB, 90%"),
            "{e}"
        );
    }
}
