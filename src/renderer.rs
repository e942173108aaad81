//! One frame of `isr`: scene upload, render targets, the passes in order, GPU
//! timing of each, and readback of the results.

use crate::gpu_types::{self, bytes_of, slice_bytes, DrawPush, FrameUniforms, MaterialGpu};
use crate::methods::gather::GatherMethod;
use crate::methods::reference::ReferencePass;
use crate::methods::rsm_gather::RsmGatherPass;
use crate::methods::rsm_splat::RsmSplatPass;
use crate::methods::FullResolution;
use crate::multires::{MultiresSettings, Upsample};
use crate::passes::rsm_tree::RsmTreePass;
use crate::passes::{
    composite::CompositePass, direct_light::DirectLightPass, gbuffer::GBufferPass, rsm::RsmPass,
    tonemap::TonemapPass, FrameContext,
};
use crate::scene::{GpuVertex, Scene};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Binding, DescriptorSet};
use crate::vk::profiler::{PassSample, Profiler};
use crate::vk::resources::texel_bytes;
use crate::vk::{Buffer, Gpu, Image, ImageDesc};
use anyhow::{bail, Context as _, Result};
use ash::vk;
use glam::{Mat4, Vec3};
use gpu_allocator::MemoryLocation;
use std::time::Instant;

/// How indirect light is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// Direct light only: indirect irradiance is zero.
    None,
    /// Stenciled gathering from N regular VPLs into the multiresolution buffer.
    MultiresGather,
    /// Basic ISR: per-frame clustered light patches, gathered by every eye patch.
    Isr,
    /// Hierarchical ISR: a per-fragment traversal of the RSM quadtree.
    Hisr,
    /// Every full-resolution pixel gathers N regular VPLs.
    RsmGather,
    /// Each VPL splats a full-screen quad, additively.
    RsmSplat,
    /// Each VPL splats a quad bounded to where it can exceed --splat-threshold.
    RsmSplatRestricted,
    /// Each VPL splats into every patch of the multiresolution buffer.
    MultiresSplat,
    /// Every pixel gathers every RSM texel (R^2 VPLs), in chunks.
    Reference,
    /// One-bounce path tracing with indirect visibility, on the CPU.
    Pathtrace,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::None => "none",
            Method::MultiresGather => "multires-gather",
            Method::Isr => "isr",
            Method::Hisr => "hisr",
            Method::RsmGather => "rsm-gather",
            Method::RsmSplat => "rsm-splat",
            Method::RsmSplatRestricted => "rsm-splat-restricted",
            Method::MultiresSplat => "multires-splat",
            Method::Reference => "reference",
            Method::Pathtrace => "pathtrace",
        }
    }

    /// Whether the method goes through the multiresolution buffer.
    pub fn uses_multires(self) -> bool {
        matches!(
            self,
            Method::MultiresGather | Method::Isr | Method::Hisr | Method::MultiresSplat
        )
    }
}

/// The light-space hierarchy (ALGORITHM.md section 4).
#[derive(Clone, Debug)]
pub struct LightTreeSettings {
    /// A patch is valid (one surface) when its children's distances to the
    /// light differ by less than this fraction of the nearest.
    pub depth_threshold: f32,
    /// ... and their normals by less than this angle (degrees).
    pub normal_threshold_deg: f32,
    /// Basic ISR's dense starting level: patches per side (a power of 2, at most R).
    pub isr_base: u32,
    /// HISR starts from 2^s x 2^s patches.
    pub start_level: u32,
    /// HISR subdivides down to 2^d x 2^d patches (`None`: 6, or log2 R if
    /// smaller). Invalid patches are always subdivided down to this depth, so
    /// it bounds the cost of discontinuities in light space.
    pub max_depth: Option<u32>,
    /// HISR's error threshold tau, as a fraction of the light's peak intensity.
    pub tau: f32,
}

impl Default for LightTreeSettings {
    fn default() -> Self {
        Self {
            depth_threshold: 0.1,
            normal_threshold_deg: 30.0,
            isr_base: 64,
            start_level: 2,
            max_depth: None,
            tau: 0.05,
        }
    }
}

/// How a regular VPL stands for its RSM patch (ALGORITHM.md section 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum VplSampling {
    /// The patch's mean position and normal, summed flux and area.
    Mean,
    /// The texel at the patch centre, flux and area scaled by the texel count.
    Point,
}

#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// RSM resolution R (R x R texels), a power of two.
    pub rsm_resolution: u32,
    pub method: Method,
    /// Multiplier applied to radiance before the PNG's sRGB encoding.
    pub exposure: f32,
    /// Shadow-map normal offset, in RSM texels at the receiver.
    pub shadow_normal_offset: f32,
    /// Constant relative depth bias of the shadow test (fraction of the distance).
    pub shadow_depth_bias: f32,
    /// PCF tap spacing in RSM texels.
    pub pcf_radius: f32,
    /// Slope-scaled shadow bias, in RSM texels along the receiver's slope.
    pub shadow_slope_bias: f32,
    /// Regular VPLs for the VPL methods: a power of 4, at most R^2.
    pub vpls: u32,
    pub vpl_sampling: VplSampling,
    pub multires: MultiresSettings,
    pub light_tree: LightTreeSettings,
    /// Restricted splats skip where a VPL's irradiance bound is below this (W/m^2).
    pub splat_threshold: f32,
    /// The reference's light-patch evaluations per submission: about 0.5 s on
    /// lavapipe at the default, milliseconds on a GPU.
    pub reference_chunk: u64,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            rsm_resolution: 512,
            method: Method::None,
            exposure: 1.0,
            shadow_normal_offset: 1.5,
            shadow_depth_bias: 5e-4,
            pcf_radius: 1.0,
            shadow_slope_bias: 2.5,
            vpls: 256,
            vpl_sampling: VplSampling::Mean,
            multires: MultiresSettings::default(),
            light_tree: LightTreeSettings::default(),
            splat_threshold: 0.01,
            reference_chunk: 1 << 26,
        }
    }
}

/// Every image a frame writes. Each is written by exactly one pass.
pub struct Targets {
    pub rsm_position: Image,
    pub rsm_normal: Image,
    pub rsm_flux: Image,
    pub rsm_depth: Image,
    pub gbuffer_position: Image,
    pub gbuffer_normal: Image,
    pub gbuffer_albedo: Image,
    pub gbuffer_depth: Image,
    pub direct: Image,
    /// Indirect irradiance E (W/m^2) at full resolution, written by the method.
    pub indirect: Image,
    pub final_radiance: Image,
    pub display: Image,
}

const COLOR_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::COLOR_ATTACHMENT.as_raw()
        | vk::ImageUsageFlags::SAMPLED.as_raw()
        | vk::ImageUsageFlags::TRANSFER_SRC.as_raw(),
);
const DEPTH_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
);

/// RSM images carry the RSM quadtree in their mip chain (level 0 = the RSM).
const RSM_USAGE: vk::ImageUsageFlags =
    vk::ImageUsageFlags::from_raw(COLOR_USAGE.as_raw() | vk::ImageUsageFlags::STORAGE.as_raw());

/// (name, format, at RSM resolution, usage) of every target, in `Targets` order.
fn target_list() -> Vec<(&'static str, vk::Format, bool, vk::ImageUsageFlags)> {
    use crate::passes::*;
    vec![
        ("rsm_position", rsm::FORMATS[0], true, RSM_USAGE),
        ("rsm_normal", rsm::FORMATS[1], true, RSM_USAGE),
        ("rsm_flux", rsm::FORMATS[2], true, RSM_USAGE),
        ("rsm_depth", vk::Format::D32_SFLOAT, true, DEPTH_USAGE),
        ("gbuffer_position", gbuffer::FORMATS[0], false, COLOR_USAGE),
        ("gbuffer_normal", gbuffer::FORMATS[1], false, COLOR_USAGE),
        ("gbuffer_albedo", gbuffer::FORMATS[2], false, COLOR_USAGE),
        ("gbuffer_depth", vk::Format::D32_SFLOAT, false, DEPTH_USAGE),
        ("direct", direct_light::FORMAT, false, COLOR_USAGE),
        (
            "indirect",
            vk::Format::R32G32B32A32_SFLOAT,
            false,
            vk::ImageUsageFlags::from_raw(
                COLOR_USAGE.as_raw()
                    | vk::ImageUsageFlags::TRANSFER_DST.as_raw()
                    | vk::ImageUsageFlags::STORAGE.as_raw(),
            ),
        ),
        ("final", composite::FORMAT, false, COLOR_USAGE),
        ("display", tonemap::FORMAT, false, COLOR_USAGE),
    ]
}

impl Targets {
    fn new(gpu: &Gpu, s: &RenderSettings) -> Result<Self> {
        let mut images = Vec::new();
        for (name, format, rsm, usage) in target_list() {
            let mips = if rsm && format != vk::Format::D32_SFLOAT {
                s.rsm_resolution.ilog2() + 1
            } else {
                1
            };
            let extent = if rsm {
                vk::Extent2D {
                    width: s.rsm_resolution,
                    height: s.rsm_resolution,
                }
            } else {
                vk::Extent2D {
                    width: s.width,
                    height: s.height,
                }
            };
            match Image::new(
                gpu,
                &ImageDesc {
                    name,
                    format,
                    extent,
                    layers: 1,
                    mips,
                    usage,
                },
            ) {
                Ok(i) => images.push(i),
                Err(e) => {
                    for mut i in images {
                        i.destroy(gpu);
                    }
                    return Err(e);
                }
            }
        }
        let mut it = images.into_iter();
        let mut next = || it.next().unwrap();
        Ok(Self {
            rsm_position: next(),
            rsm_normal: next(),
            rsm_flux: next(),
            rsm_depth: next(),
            gbuffer_position: next(),
            gbuffer_normal: next(),
            gbuffer_albedo: next(),
            gbuffer_depth: next(),
            direct: next(),
            indirect: next(),
            final_radiance: next(),
            display: next(),
        })
    }

    fn all_mut(&mut self) -> [&mut Image; 12] {
        [
            &mut self.rsm_position,
            &mut self.rsm_normal,
            &mut self.rsm_flux,
            &mut self.rsm_depth,
            &mut self.gbuffer_position,
            &mut self.gbuffer_normal,
            &mut self.gbuffer_albedo,
            &mut self.gbuffer_depth,
            &mut self.direct,
            &mut self.indirect,
            &mut self.final_radiance,
            &mut self.display,
        ]
    }
}

pub struct Samplers {
    /// For `texelFetch` inputs (a combined image sampler needs some sampler).
    pub nearest: vk::Sampler,
    /// Hardware 2x2 PCF on reversed-Z depth: passes where reference >= stored.
    pub shadow: vk::Sampler,
    /// Scene textures: bilinear, repeat.
    pub texture: vk::Sampler,
}

impl Samplers {
    fn new(gpu: &Gpu) -> Result<Self> {
        let base = vk::SamplerCreateInfo::default()
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(0.0);
        let d = &gpu.device;
        unsafe {
            Ok(Self {
                nearest: d.create_sampler(&base, None)?,
                shadow: d.create_sampler(
                    &base
                        .mag_filter(vk::Filter::LINEAR)
                        .min_filter(vk::Filter::LINEAR)
                        .compare_enable(true)
                        .compare_op(vk::CompareOp::GREATER_OR_EQUAL),
                    None,
                )?,
                texture: d.create_sampler(
                    &base
                        .mag_filter(vk::Filter::LINEAR)
                        .min_filter(vk::Filter::LINEAR)
                        .address_mode_u(vk::SamplerAddressMode::REPEAT)
                        .address_mode_v(vk::SamplerAddressMode::REPEAT),
                    None,
                )?,
            })
        }
    }

    fn destroy(&self, gpu: &Gpu) {
        unsafe {
            gpu.device.destroy_sampler(self.nearest, None);
            gpu.device.destroy_sampler(self.shadow, None);
            gpu.device.destroy_sampler(self.texture, None);
        }
    }
}

/// What passes read that the renderer owns: frame uniforms, targets, samplers.
pub struct FrameInputs<'a> {
    pub uniforms: &'a Buffer,
    pub targets: &'a Targets,
    pub samplers: &'a Samplers,
}

/// One indexed draw of a mesh instance.
pub struct Draw {
    pub first_index: u32,
    pub index_count: u32,
    pub vertex_offset: i32,
    pub double_sided: bool,
    pub push: DrawPush,
}

/// The scene on the GPU: one vertex and one index buffer for all meshes, the
/// materials, the textures, and the descriptor set the scene passes share
/// (binding 0: frame uniforms, 1: materials, 2: textures).
pub struct SceneGpu {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub materials: Buffer,
    /// At least one (a white texel when the scene has no textures).
    pub textures: Vec<Image>,
    pub draws: Vec<Draw>,
    pub set: DescriptorSet,
}

impl SceneGpu {
    fn new(gpu: &Gpu, scene: &Scene, uniforms: &Buffer, sampler: vk::Sampler) -> Result<Self> {
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
            .map(|inst| {
                let mesh = &scene.meshes[inst.mesh];
                let (first_index, index_count, vertex_offset) = ranges[inst.mesh];
                Draw {
                    first_index,
                    index_count,
                    vertex_offset,
                    double_sided: scene.materials[mesh.material].double_sided,
                    push: DrawPush {
                        world_from_object: inst.world_from_object.to_cols_array_2d(),
                        material: mesh.material as u32,
                        pad: [0; 3],
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
                pad: [0; 3],
            })
            .collect();
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
        let white = crate::scene::Texture {
            name: "white".into(),
            width: 1,
            height: 1,
            rgba8: vec![255; 4],
        };
        let sources: Vec<&crate::scene::Texture> = if scene.textures.is_empty() {
            vec![&white]
        } else {
            scene.textures.iter().collect()
        };
        let mut textures = Vec::new();
        for t in sources {
            textures.push(upload_texture(gpu, t)?);
        }
        let vertices = Buffer::with_data(
            gpu,
            "vertices",
            slice_bytes(&vertices),
            vk::BufferUsageFlags::VERTEX_BUFFER,
        )?;
        let indices = Buffer::with_data(
            gpu,
            "indices",
            slice_bytes(&indices),
            vk::BufferUsageFlags::INDEX_BUFFER,
        )?;
        let materials = Buffer::with_data(
            gpu,
            "materials",
            slice_bytes(&materials),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let views: Vec<vk::ImageView> = textures.iter().map(|t| t.view).collect();
        let set = DescriptorSet::new(
            gpu,
            "scene",
            &[
                Binding::Uniform(uniforms),
                Binding::Storage(&materials),
                Binding::SampledArray(&views, sampler),
            ],
        )?;
        Ok(Self {
            vertices,
            indices,
            materials,
            textures,
            draws,
            set,
        })
    }

    pub fn texture_count(&self) -> usize {
        self.textures.len()
    }

    fn destroy(&mut self, gpu: &Gpu) {
        self.vertices.destroy(gpu);
        self.indices.destroy(gpu);
        self.materials.destroy(gpu);
        for t in &mut self.textures {
            t.destroy(gpu);
        }
        self.set.destroy(gpu);
    }
}

fn upload_texture(gpu: &Gpu, t: &crate::scene::Texture) -> Result<Image> {
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
    let result = gpu.run_once(|cmd| unsafe {
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
    });
    staging.destroy(gpu);
    result.map(|_| image)
}

/// GPU numbers of every frame rendered, and the CPU-measured wall time of each
/// (submit to fence).
#[derive(Clone, Debug, Default)]
pub struct FrameStats {
    pub frames: Vec<Vec<PassSample>>,
    pub wall_ms: Vec<f64>,
    /// Multiresolution patches per level of the last frame.
    pub patches_per_level: Option<Vec<u32>>,
}

impl FrameStats {
    /// Median over frames of the summed time of all passes, or of the passes
    /// that exist only for indirect light; `None` without timestamps.
    pub fn gpu_ms_median(&self, indirect_only: bool) -> Option<f64> {
        let sums: Vec<f64> = self
            .frames
            .iter()
            .filter_map(|f| {
                f.iter()
                    .filter(|p| !indirect_only || p.kind.indirect)
                    .map(|p| p.gpu_ms)
                    .try_fold(0.0, |acc, ms| Some(acc + ms?))
            })
            .collect();
        crate::report::median(&sums)
    }
}

/// Image contents copied back to the host, rows top to bottom, RGBA f32.
pub struct Readback {
    pub width: u32,
    pub height: u32,
    pub final_radiance: Vec<[f32; 4]>,
    pub direct: Vec<[f32; 4]>,
    pub indirect: Vec<[f32; 4]>,
    pub albedo: Vec<[f32; 4]>,
    pub normal: Vec<[f32; 4]>,
    /// xyz world position, w view depth (0 for background).
    pub position: Vec<[f32; 4]>,
    /// The tonemapped 8-bit sRGB image.
    pub display: Vec<u8>,
    pub rsm: RsmReadback,
}

pub struct RsmReadback {
    pub resolution: u32,
    /// xyz position, w area A_j (0 where nothing was seen).
    pub position: Vec<[f32; 4]>,
    /// xyz normal, w 1 where geometry was seen.
    pub normal: Vec<[f32; 4]>,
    /// rgb flux Phi_j, a solid angle dw_j.
    pub flux: Vec<[f32; 4]>,
}

pub struct Renderer<'g> {
    gpu: &'g Gpu,
    pub settings: RenderSettings,
    pub scene: SceneGpu,
    pub targets: Targets,
    samplers: Samplers,
    uniforms: Buffer,
    frame_uniforms: FrameUniforms,
    rsm: RsmPass,
    gbuffer: GBufferPass,
    direct: DirectLightPass,
    composite: CompositePass,
    tonemap: TonemapPass,
    rsm_tree: Option<RsmTreePass>,
    /// The passes of a method that gathers into the multiresolution buffer.
    pub gather_method: Option<GatherMethod>,
    /// The pass of a full-resolution method.
    full_resolution: Option<FullResolution>,
    reference: Option<ReferencePass>,
    profiler: Profiler,
    /// One frame: submitted in order, each waited for (one, except for the
    /// reference's chunks).
    frame_cmds: Vec<vk::CommandBuffer>,
}

/// Where `render_frames` is, for progress reports.
#[derive(Clone, Copy, Debug)]
pub struct FrameProgress {
    /// Frames finished (1-based once a frame is done).
    pub frame: u32,
    pub frames: u32,
    /// Submissions of the current frame finished, of `submissions`.
    pub submission: u32,
    pub submissions: u32,
}

/// Passes a frame can hold; the profiler's query pools are this large.
const MAX_PASSES: u32 = 32;

/// Checks `settings` against the device and returns an error that says what to change.
pub fn check_settings(gpu: &Gpu, s: &RenderSettings) -> Result<()> {
    let l = gpu.limits();
    let max_w = l.max_image_dimension2_d.min(l.max_framebuffer_width);
    let max_h = l.max_image_dimension2_d.min(l.max_framebuffer_height);
    if s.width == 0 || s.height == 0 {
        bail!(
            "resolution {}x{} is empty: width and height must be at least 1",
            s.width,
            s.height
        );
    }
    if s.width > max_w || s.height > max_h {
        bail!(
            "resolution {}x{} exceeds what {} can render ({max_w}x{max_h}); choose a smaller --width/--height",
            s.width,
            s.height,
            gpu.info.name
        );
    }
    let r = s.rsm_resolution;
    if !r.is_power_of_two() || r < 16 {
        bail!("--rsm {r}: the RSM resolution must be a power of two of at least 16 (it is the root of a quadtree)");
    }
    if r > max_w.min(max_h) {
        bail!(
            "--rsm {r} exceeds this device's image limit of {}",
            max_w.min(max_h)
        );
    }
    let needed: u64 = target_list()
        .iter()
        .map(|(_, f, rsm, _)| {
            // RSM color images carry the quadtree: a mip chain, 4/3 the texels.
            let texels = if *rsm { (r as u64).pow(2) * 4 / 3 } else { s.width as u64 * s.height as u64 };
            texels * texel_bytes(*f)
        })
        .sum::<u64>()
        // readback buffers for the largest layers
        + s.width as u64 * s.height as u64 * 16 * 2
        + if s.method.uses_multires() { multires_bytes(s) } else { 0 };
    let props = unsafe {
        gpu.instance
            .get_physical_device_memory_properties(gpu.physical)
    };
    let heap = props.memory_heaps[..props.memory_heap_count as usize]
        .iter()
        .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
        .map(|h| h.size)
        .max()
        .unwrap_or(0);
    if heap > 0 && needed > heap / 10 * 9 {
        bail!(
            "resolution {}x{} with --rsm {r} needs about {} MiB of GPU memory; the device has {} MiB. Choose a smaller resolution",
            s.width,
            s.height,
            needed >> 20,
            heap >> 20
        );
    }
    if !(s.exposure.is_finite() && s.exposure >= 0.0) {
        bail!("--exposure must be a finite non-negative number");
    }
    if s.method == Method::MultiresSplat && !s.multires.stencil {
        bail!("--stencil off measures the stenciled gathers; multires-splat always splats through the stencil");
    }
    if !(s.splat_threshold.is_finite() && s.splat_threshold >= 0.0) {
        bail!("--splat-threshold must be a finite non-negative irradiance (W/m^2)");
    }
    if !matches!(
        s.method,
        Method::None | Method::Reference | Method::Pathtrace
    ) {
        let side = (s.vpls as f64).sqrt() as u32;
        if s.vpls == 0 || side * side != s.vpls || !side.is_power_of_two() {
            bail!("--vpls {}: the number of regular VPLs must be a power of 4 (1, 4, 16, ..., 4096, ...)", s.vpls);
        }
        if side > r {
            bail!(
                "--vpls {} needs more RSM texels than --rsm {r} has ({} at most)",
                s.vpls,
                r as u64 * r as u64
            );
        }
        let levels = levels_of(s);
        if levels == 0
            || levels >= crate::multires::MAX_LEVELS
            || s.width >> levels == 0
            || s.height >> levels == 0
        {
            bail!(
                "--levels {levels}: the coarsest level must be at least 1 and its texels ({0}x{0} pixels) no larger than the image",
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
        let max_depth = hisr_max_depth(s);
        if s.method == Method::Hisr && (max_depth > top || lt.start_level > max_depth) {
            bail!(
                "--start-level {} and --max-depth {max_depth} must satisfy start <= max <= log2(--rsm) = {top}",
                lt.start_level
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
    }
    Ok(())
}

/// GPU memory of the multiresolution buffer: (L + 1) layers of illumination
/// (RGBA32F), evaluation counts (R32UI) and stencil, plus five geometry mip
/// chains (four RGBA32F, one R32UI).
fn multires_bytes(s: &RenderSettings) -> u64 {
    let pixels = s.width as u64 * s.height as u64;
    let layers = levels_of(s).min(crate::multires::MAX_LEVELS) as u64 + 1;
    layers * pixels * (16 + 4 + 4) + pixels * 4 / 3 * (4 * 16 + 4)
}

/// HISR's deepest level: `--max-depth`, by default 6 or log2 R if smaller.
pub fn hisr_max_depth(s: &RenderSettings) -> u32 {
    s.light_tree
        .max_depth
        .unwrap_or(6.min(s.rsm_resolution.max(1).ilog2()))
}

/// The regular VPLs a method uses: every RSM texel for `reference`.
pub fn effective_vpls(s: &RenderSettings) -> u32 {
    match s.method {
        Method::Reference => s.rsm_resolution * s.rsm_resolution,
        _ => s.vpls,
    }
}

/// The RSM quadtree level (mip) Basic ISR starts from.
pub fn isr_base_mip(s: &RenderSettings) -> u32 {
    s.rsm_resolution.ilog2() - s.light_tree.isr_base.clamp(1, s.rsm_resolution).ilog2()
}

/// The coarsest level L of the multiresolution buffer for these settings.
pub fn levels_of(s: &RenderSettings) -> u32 {
    s.multires
        .levels
        .unwrap_or_else(|| crate::multires::default_levels(s.width, s.height))
}

/// World -> clip for Vulkan: y flipped (framebuffer y points down), reversed-Z
/// with an infinite far plane (depth 1 at `near`, 0 at infinity).
fn projection(fov_y: f32, aspect: f32, near: f32) -> Mat4 {
    Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0))
        * Mat4::perspective_infinite_reverse_rh(fov_y, aspect, near)
}

/// The largest RSM half field of view; wider cones are cut (a warning says so).
pub const MAX_RSM_HALF_FOV: f32 = 80.0 * std::f32::consts::PI / 180.0;

pub fn frame_uniforms(scene: &Scene, s: &RenderSettings) -> FrameUniforms {
    let cam = &scene.camera;
    let view = cam.world_from_camera.inverse();
    let camera_view_proj = projection(cam.yfov, s.width as f32 / s.height as f32, cam.znear) * view;
    let l = &scene.light;
    let up = if l.direction.dot(Vec3::Y).abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let light_view = Mat4::look_at_rh(l.position, l.position + l.direction, up);
    let half_fov = l.outer_cone.min(MAX_RSM_HALF_FOV);
    let extent = scene.bounds().map_or(1.0, |(lo, hi)| (hi - lo).length());
    let light_near = (extent * 1e-4).max(1e-6);
    let light_view_proj = projection(2.0 * half_fov, 1.0, light_near) * light_view;
    let (scale, offset) = l.cone_scale_offset();
    let r = s.rsm_resolution as f32;
    let side = ((effective_vpls(s) as f64).sqrt() as u32).max(1);
    let vpl_level = s.rsm_resolution.max(side).ilog2() - side.ilog2();
    let mut flags = 0;
    if s.vpl_sampling == VplSampling::Point {
        flags |= gpu_types::HIERARCHY_POINT_VPLS;
    }
    if s.multires.upsample == Upsample::Interpolated {
        flags |= gpu_types::HIERARCHY_INTERPOLATE;
    }
    if !s.multires.stencil {
        flags |= gpu_types::HIERARCHY_STENCIL_OFF;
    }
    let chord = 2.0 * (0.5 * s.multires.normal_threshold_deg.to_radians()).sin();
    let lt = &s.light_tree;
    let top = s.rsm_resolution.ilog2();
    FrameUniforms {
        camera_view_proj: camera_view_proj.to_cols_array_2d(),
        light_view_proj: light_view_proj.to_cols_array_2d(),
        camera_position: cam.position().extend(1.0).to_array(),
        camera_forward: cam.forward().extend(0.0).to_array(),
        light_position: l.position.extend(l.range.unwrap_or(0.0)).to_array(),
        light_direction: l.direction.extend(0.0).to_array(),
        light_intensity: (l.color * l.intensity).extend(0.0).to_array(),
        light_cone: [scale, offset, half_fov.tan(), r],
        shadow: [
            s.shadow_normal_offset,
            s.shadow_depth_bias,
            s.pcf_radius,
            s.shadow_slope_bias,
        ],
        exposure: [s.exposure, 0.0, 0.0, 0.0],
        size: [s.width, s.height, s.rsm_resolution, 0],
        refine: [s.multires.depth_threshold, chord, 0.0, 0.0],
        hierarchy: [levels_of(s) as i32, vpl_level as i32, side as i32, flags],
        light_tree: [
            crate::methods::hisr::subdivision_threshold(lt.tau, s.rsm_resolution),
            lt.depth_threshold,
            lt.normal_threshold_deg.to_radians().cos(),
            (l.color * l.intensity).max_element(),
        ],
        splat: [s.splat_threshold, 0.0, 0.0, 0.0],
        light_levels: [
            lt.start_level as i32,
            hisr_max_depth(s) as i32,
            isr_base_mip(s) as i32,
            top as i32,
        ],
    }
}

impl<'g> Renderer<'g> {
    pub fn new(gpu: &'g Gpu, scene: &Scene, settings: &RenderSettings) -> Result<Self> {
        if settings.method == Method::Pathtrace {
            bail!("method pathtrace runs on the CPU (isr::pathtrace::render), not in the Vulkan renderer");
        }
        check_settings(gpu, settings)?;
        let frame_uniforms = frame_uniforms(scene, settings);
        let mut uniforms = Buffer::new(
            gpu,
            "frame uniforms",
            std::mem::size_of::<FrameUniforms>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        uniforms.write(0, bytes_of(&frame_uniforms));
        let samplers = Samplers::new(gpu)?;
        let scene_gpu = SceneGpu::new(gpu, scene, &uniforms, samplers.texture)
            .context("uploading the scene")?;
        let targets = Targets::new(gpu, settings)?;
        let rsm = RsmPass::new(gpu, &scene_gpu)?;
        let gbuffer = GBufferPass::new(gpu, &scene_gpu)?;
        let direct = DirectLightPass::new(gpu, &uniforms, &targets, &samplers)?;
        let composite = CompositePass::new(gpu, &uniforms, &targets, &samplers)?;
        let tonemap = TonemapPass::new(gpu, &uniforms, &targets, &samplers)?;
        let rsm_tree = match settings.method {
            Method::None => None,
            _ => Some(RsmTreePass::new(gpu, &uniforms, &targets)?),
        };
        let inputs = FrameInputs {
            uniforms: &uniforms,
            targets: &targets,
            samplers: &samplers,
        };
        let gather_method = if settings.method.uses_multires() {
            Some(GatherMethod::new(gpu, &inputs, settings)?)
        } else {
            None
        };
        let full_resolution = match settings.method {
            Method::RsmGather => Some(FullResolution::Gather(RsmGatherPass::new(gpu, &inputs)?)),
            Method::RsmSplat | Method::RsmSplatRestricted => {
                Some(FullResolution::Splat(RsmSplatPass::new(
                    gpu,
                    &inputs,
                    settings.vpls,
                    settings.method == Method::RsmSplatRestricted,
                )?))
            }
            _ => None,
        };
        let reference = match settings.method {
            Method::Reference => Some(ReferencePass::new(
                gpu,
                &inputs,
                settings.width,
                settings.height,
                settings.rsm_resolution,
                settings.reference_chunk.max(1),
            )?),
            _ => None,
        };
        let chunks = reference.as_ref().map_or(0, |r| r.chunks.len() as u32);
        let profiler = Profiler::new(gpu, MAX_PASSES + chunks)?;
        let mut r = Self {
            gpu,
            settings: settings.clone(),
            scene: scene_gpu,
            targets,
            samplers,
            uniforms,
            frame_uniforms,
            rsm,
            gbuffer,
            direct,
            composite,
            tonemap,
            rsm_tree,
            gather_method,
            full_resolution,
            reference,
            profiler,
            frame_cmds: Vec::new(),
        };
        if settings.method == Method::None {
            r.clear_indirect()?;
        }
        r.record_frame()?;
        Ok(r)
    }

    pub fn uniforms(&self) -> &FrameUniforms {
        &self.frame_uniforms
    }

    /// Method `none`: the indirect image holds zero, written once.
    fn clear_indirect(&self) -> Result<()> {
        let gpu = self.gpu;
        let image = &self.targets.indirect;
        gpu.run_once(|cmd| barrier::clear_color(gpu, cmd, image, Use::READ_ONLY))
    }

    /// Records the frame once; every `render_frames` submission replays it.
    fn record_frame(&mut self) -> Result<()> {
        let gpu = self.gpu;
        let begin = |cmds: &mut Vec<vk::CommandBuffer>| -> Result<vk::CommandBuffer> {
            let cmd = gpu.allocate_command_buffer()?;
            unsafe {
                gpu.device
                    .begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())?
            };
            cmds.push(cmd);
            Ok(cmd)
        };
        let mut cmds = Vec::new();
        let mut cmd = begin(&mut cmds)?;
        let ctx = |cmd| FrameContext {
            gpu,
            cmd,
            scene: &self.scene,
            targets: &self.targets,
        };
        let p = &mut self.profiler;
        p.begin_frame(gpu, cmd);
        self.rsm.record(&ctx(cmd), p);
        self.gbuffer.record(&ctx(cmd), p);
        self.direct.record(&ctx(cmd), p);
        if let Some(t) = &self.rsm_tree {
            t.record(&ctx(cmd), p);
        }
        // Method `none`: indirect stays zero (cleared once in `new`).
        if let Some(m) = &self.gather_method {
            m.record(&ctx(cmd), p);
        }
        if let Some(m) = &self.full_resolution {
            m.record(&ctx(cmd), p);
        }
        if let Some(r) = &self.reference {
            for i in 0..r.chunks.len() {
                if i > 0 {
                    unsafe { gpu.device.end_command_buffer(cmd)? };
                    cmd = begin(&mut cmds)?;
                }
                r.record_chunk(&ctx(cmd), p, i);
            }
        }
        self.composite.record(&ctx(cmd), p);
        self.tonemap.record(&ctx(cmd), p);
        unsafe { gpu.device.end_command_buffer(cmd)? };
        self.frame_cmds = cmds;
        Ok(())
    }

    /// Renders `n` frames, each submission waited for, and returns every
    /// frame's per-pass numbers. `progress` is called after each submission.
    pub fn render_frames(
        &mut self,
        n: u32,
        mut progress: impl FnMut(FrameProgress),
    ) -> Result<FrameStats> {
        let mut stats = FrameStats::default();
        let submissions = self.frame_cmds.len() as u32;
        for i in 0..n {
            let start = Instant::now();
            for (k, cmd) in self.frame_cmds.iter().enumerate() {
                self.gpu.submit_and_wait(*cmd)?;
                let done = k as u32 + 1;
                progress(FrameProgress {
                    frame: i + (done == submissions) as u32,
                    frames: n,
                    submission: done,
                    submissions,
                });
            }
            stats.wall_ms.push(start.elapsed().as_secs_f64() * 1e3);
            stats.frames.push(self.profiler.read(self.gpu)?);
            if let Some(m) = &self.gather_method {
                stats.patches_per_level = Some(m.multires.buffer.patch_counts());
            }
        }
        Ok(stats)
    }

    /// Copies every output back to the host. Call after `render_frames`.
    pub fn readback(&self) -> Result<Readback> {
        let t = &self.targets;
        let images: [&Image; 10] = [
            &t.final_radiance,
            &t.direct,
            &t.indirect,
            &t.gbuffer_albedo,
            &t.gbuffer_normal,
            &t.gbuffer_position,
            &t.display,
            &t.rsm_position,
            &t.rsm_normal,
            &t.rsm_flux,
        ];
        let regions: Vec<Region> = images.iter().map(|i| Region::color(i)).collect();
        let mut raw = read_regions(self.gpu, &regions)?.into_iter();
        let mut next = || raw.next().unwrap();
        let final_radiance = to_rgba_f32(&next(), t.final_radiance.format);
        let direct = to_rgba_f32(&next(), t.direct.format);
        let indirect = to_rgba_f32(&next(), t.indirect.format);
        let albedo = to_rgba_f32(&next(), t.gbuffer_albedo.format);
        let normal = to_rgba_f32(&next(), t.gbuffer_normal.format);
        let position = to_rgba_f32(&next(), t.gbuffer_position.format);
        let display = next();
        let rsm = RsmReadback {
            resolution: self.settings.rsm_resolution,
            position: to_rgba_f32(&next(), t.rsm_position.format),
            normal: to_rgba_f32(&next(), t.rsm_normal.format),
            flux: to_rgba_f32(&next(), t.rsm_flux.format),
        };
        Ok(Readback {
            width: self.settings.width,
            height: self.settings.height,
            final_radiance,
            direct,
            indirect,
            albedo,
            normal,
            position,
            display,
            rsm,
        })
    }
}

/// One mip level of one layer of an image, to copy to the host.
#[derive(Clone, Copy)]
pub struct Region<'a> {
    pub image: &'a Image,
    /// The image's resting state, restored after the copy.
    pub from: Use,
    pub mip: u32,
    pub layer: u32,
    /// COLOR, or STENCIL for the stencil of a depth/stencil image.
    pub aspect: vk::ImageAspectFlags,
}

impl<'a> Region<'a> {
    /// Mip 0 of a single-layer color image in the `READ_ONLY` convention state.
    pub fn color(image: &'a Image) -> Self {
        Self::mip(image, 0)
    }

    pub fn mip(image: &'a Image, mip: u32) -> Self {
        Self {
            image,
            from: Use::READ_ONLY,
            mip,
            layer: 0,
            aspect: vk::ImageAspectFlags::COLOR,
        }
    }

    pub fn layer(image: &'a Image, layer: u32) -> Self {
        Self {
            layer,
            ..Self::color(image)
        }
    }

    fn bytes(&self) -> u64 {
        let e = self.image.mip_extent(self.mip);
        let texel = if self.aspect == vk::ImageAspectFlags::STENCIL {
            1
        } else {
            texel_bytes(self.image.format)
        };
        e.width as u64 * e.height as u64 * texel
    }
}

/// Copies `regions` into host memory in one submission; each image is back in
/// its resting state afterwards.
pub fn read_regions(gpu: &Gpu, regions: &[Region]) -> Result<Vec<Vec<u8>>> {
    let mut buffers = Vec::new();
    for r in regions {
        buffers.push(Buffer::new(
            gpu,
            "readback",
            r.bytes(),
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?);
    }
    // One transition per image, however many of its regions are read.
    let mut images: Vec<(&Image, Use)> = Vec::new();
    for r in regions {
        if !images.iter().any(|(i, _)| i.image == r.image.image) {
            images.push((r.image, r.from));
        }
    }
    let result = gpu.run_once(|cmd| unsafe {
        let to_src: Vec<_> = images
            .iter()
            .map(|(i, from)| barrier::image(i, *from, Use::TRANSFER_SRC))
            .collect();
        barrier::images(gpu, cmd, &to_src);
        for (r, buf) in regions.iter().zip(&buffers) {
            let e = r.image.mip_extent(r.mip);
            let region = vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: r.aspect,
                    mip_level: r.mip,
                    base_array_layer: r.layer,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D {
                    width: e.width,
                    height: e.height,
                    depth: 1,
                });
            gpu.device.cmd_copy_image_to_buffer(
                cmd,
                r.image.image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buf.buffer,
                &[region],
            );
        }
        let back: Vec<_> = images
            .iter()
            .map(|(i, from)| barrier::image(i, Use::TRANSFER_SRC, *from))
            .collect();
        barrier::images(gpu, cmd, &back);
        barrier::copies_to_host(gpu, cmd);
    });
    let out = buffers.iter().map(|b| b.mapped().to_vec()).collect();
    for mut b in buffers {
        b.destroy(gpu);
    }
    result.map(|_| out)
}

/// Copies a device-local buffer to the host (after the frames that wrote it).
pub fn read_buffer(gpu: &Gpu, buffer: &Buffer) -> Result<Vec<u8>> {
    let mut staging = Buffer::new(
        gpu,
        "readback",
        buffer.size,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?;
    let result = gpu.run_once(|cmd| unsafe {
        gpu.device.cmd_copy_buffer(
            cmd,
            buffer.buffer,
            staging.buffer,
            &[vk::BufferCopy::default().size(buffer.size)],
        );
        barrier::copies_to_host(gpu, cmd);
    });
    let bytes = staging.mapped().to_vec();
    staging.destroy(gpu);
    result.map(|_| bytes)
}

fn to_u32(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

fn to_rgba_f32(bytes: &[u8], format: vk::Format) -> Vec<[f32; 4]> {
    match format {
        vk::Format::R32G32B32A32_SFLOAT => bytes
            .chunks_exact(16)
            .map(|c| {
                std::array::from_fn(|i| f32::from_le_bytes(c[i * 4..i * 4 + 4].try_into().unwrap()))
            })
            .collect(),
        vk::Format::R16G16B16A16_SFLOAT => bytes
            .chunks_exact(8)
            .map(|c| {
                std::array::from_fn(|i| {
                    half::f16::from_le_bytes(c[i * 2..i * 2 + 2].try_into().unwrap()).to_f32()
                })
            })
            .collect(),
        other => panic!("readback of {other:?} as f32 is not implemented"),
    }
}

impl Renderer<'_> {
    /// The light patches Basic ISR chose in the last frame (`None` for other methods).
    pub fn isr_chosen(&self) -> Result<Option<Vec<gpu_types::LightPatch>>> {
        let Some(isr) = self.gather_method.as_ref().and_then(|m| m.isr.as_ref()) else {
            return Ok(None);
        };
        let bytes = read_buffer(self.gpu, &isr.chosen)?;
        let size = std::mem::size_of::<gpu_types::LightPatch>();
        let start = gpu_types::CHOSEN_PATCHES_HEADER;
        // Clamped to the capacity: before any frame the count is not yet written.
        let capacity = (bytes.len() - start) / size;
        let count = (u32::from_le_bytes(bytes[..4].try_into().unwrap()) as usize).min(capacity);
        Ok(Some(
            bytes[start..start + count * size]
                .chunks_exact(size)
                .map(|c| {
                    let f: Vec<f32> = c
                        .chunks_exact(4)
                        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                        .collect();
                    gpu_types::LightPatch {
                        position_area: f[0..4].try_into().unwrap(),
                        normal: f[4..8].try_into().unwrap(),
                        flux: f[8..12].try_into().unwrap(),
                    }
                })
                .collect(),
        ))
    }

    /// How many light patches Basic ISR chose in the last frame.
    pub fn isr_chosen_count(&self) -> Result<Option<u32>> {
        Ok(self.isr_chosen()?.map(|c| c.len() as u32))
    }

    /// The multiresolution buffer of the last frame, if the method has one.
    pub fn readback_multires(&self) -> Result<Option<MultiresReadback>> {
        let Some(mg) = &self.gather_method else {
            return Ok(None);
        };
        let m = &mg.multires.buffer;
        let t = &self.targets;
        let n = m.levels + 1;
        let mut regions = Vec::new();
        regions.extend((0..n).map(|l| Region::layer(&m.illumination, l)));
        regions.extend((0..n).map(|l| Region::layer(&m.evaluations, l)));
        regions.extend((0..n).map(|l| Region {
            from: Use::STENCIL_READ_ONLY,
            aspect: vk::ImageAspectFlags::STENCIL,
            ..Region::layer(&m.stencil, l)
        }));
        for image in [&m.geo_mean, &m.geo_normal, &m.geo_flags] {
            regions.extend((0..n).map(|l| Region::mip(image, l)));
        }
        let rsm_levels = t.rsm_position.mips;
        for k in 0..rsm_levels {
            for image in [&t.rsm_position, &t.rsm_normal, &t.rsm_flux] {
                regions.push(Region::mip(image, k));
            }
        }
        let mut raw = read_regions(self.gpu, &regions)?.into_iter();
        let rgba = vk::Format::R32G32B32A32_SFLOAT;
        let illumination: Vec<_> = (0..n)
            .map(|_| to_rgba_f32(&raw.next().unwrap(), rgba))
            .collect();
        // Counts stored as f32 (exact below 2^24).
        let evaluations: Vec<Vec<u32>> = (0..n)
            .map(|_| {
                to_u32(&raw.next().unwrap())
                    .into_iter()
                    .map(|b| f32::from_bits(b) as u32)
                    .collect()
            })
            .collect();
        let stencil: Vec<Vec<u8>> = (0..n).map(|_| raw.next().unwrap()).collect();
        let geo_mean: Vec<_> = (0..n)
            .map(|_| to_rgba_f32(&raw.next().unwrap(), rgba))
            .collect();
        let geo_normal: Vec<_> = (0..n)
            .map(|_| to_rgba_f32(&raw.next().unwrap(), rgba))
            .collect();
        let geo_flags: Vec<Vec<u32>> = (0..n).map(|_| to_u32(&raw.next().unwrap())).collect();
        let rsm_tree = (0..rsm_levels)
            .map(|_| std::array::from_fn(|_| to_rgba_f32(&raw.next().unwrap(), rgba)))
            .collect();
        Ok(Some(MultiresReadback {
            width: self.settings.width,
            height: self.settings.height,
            levels: m.levels,
            illumination,
            evaluations,
            stencil,
            geo_mean,
            geo_normal,
            geo_flags,
            rsm_tree,
        }))
    }
}

impl Drop for Renderer<'_> {
    fn drop(&mut self) {
        let gpu = self.gpu;
        unsafe {
            let _ = gpu.device.device_wait_idle();
            if !self.frame_cmds.is_empty() {
                gpu.device
                    .free_command_buffers(gpu.command_pool, &self.frame_cmds);
            }
        }
        self.rsm.destroy(gpu);
        self.gbuffer.destroy(gpu);
        self.direct.destroy(gpu);
        self.composite.destroy(gpu);
        self.tonemap.destroy(gpu);
        if let Some(t) = &mut self.rsm_tree {
            t.destroy(gpu);
        }
        if let Some(m) = &mut self.gather_method {
            m.destroy(gpu);
        }
        if let Some(m) = &mut self.full_resolution {
            m.destroy(gpu);
        }
        if let Some(r) = &mut self.reference {
            r.destroy(gpu);
        }
        self.profiler.destroy(gpu);
        for i in self.targets.all_mut() {
            i.destroy(gpu);
        }
        self.scene.destroy(gpu);
        self.uniforms.destroy(gpu);
        self.samplers.destroy(gpu);
    }
}

/// The multiresolution buffer copied back to the host (for tests and debug views).
pub struct MultiresReadback {
    pub width: u32,
    pub height: u32,
    pub levels: u32,
    /// Per layer l, the whole W x H layer (the used corner is (W >> l) x (H >> l)).
    pub illumination: Vec<Vec<[f32; 4]>>,
    /// Per layer l, light patches each texel evaluated (W x H).
    pub evaluations: Vec<Vec<u32>>,
    /// Per layer, stencil values, W x H.
    pub stencil: Vec<Vec<u8>>,
    /// Per mip level l, (W >> l) x (H >> l) texels.
    pub geo_mean: Vec<Vec<[f32; 4]>>,
    pub geo_normal: Vec<Vec<[f32; 4]>>,
    pub geo_flags: Vec<Vec<u32>>,
    /// RSM quadtree levels (level k is (R >> k)^2 texels): position, normal, flux.
    pub rsm_tree: Vec<[Vec<[f32; 4]>; 3]>,
}
