//! Methods `rsm-splat` and `rsm-splat-restricted` (docs/algorithm.md section
//! 5): each of the N regular VPLs draws a quad, full screen or bounded to
//! where its contribution can exceed `--splat-threshold` (D&S 2006), and its
//! fragments add that VPL's irradiance into the float target (blend ONE + ONE).
//! Pass `rsm-splat`: `shaders/rsm_splat/splat.vert` + `shaders/rsm_splat/splat.frag`, one
//! instanced draw (instance = VPL). Reads the G-buffer and RSM quadtree;
//! writes `indirect` (barriers below).

use super::rsm_gather::full_resolution_bindings;
use super::{Descriptor, IndirectMethod};
use crate::frame::{FrameContext, Setup};
use crate::passes::{begin_rendering, Attachments, INDIRECT_GRAPHICS};
use crate::regular_vpls::RegularVpls;
use crate::settings::params::{AnyParam, DefaultValue, Param, Range};
use crate::settings::{Method, RenderSettings};
use crate::vk::barrier::{self, Use};
use crate::vk::pipeline::{Blend, GraphicsDesc, PassPipeline, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::Gpu;
use anyhow::{bail, Result};
use ash::vk;

/// Restricted splats skip where a VPL's irradiance bound is below this (W/m^2).
pub const THRESHOLD: Param<f32> = Param {
    name: "splat-threshold",
    help: "Restricted splats: a VPL's quad covers only where its irradiance bound \
           Phi / (pi d^2) exceeds this (W/m^2); 0 gives full-screen splats",
    default: DefaultValue::Fixed(0.01),
    range: Range::at_least(0.0),
};

const RESTRICTED_PARAMS: &[&dyn AnyParam] = &[&THRESHOLD];

/// `rsm-splat` and `rsm-splat-restricted`: one module, two methods.
pub struct RsmSplatMethod {
    restricted: bool,
}

pub static RSM_SPLAT: RsmSplatMethod = RsmSplatMethod { restricted: false };
pub static RSM_SPLAT_RESTRICTED: RsmSplatMethod = RsmSplatMethod { restricted: true };

impl Descriptor for RsmSplatMethod {
    fn key(&self) -> Method {
        match self.restricted {
            false => Method::new("rsm-splat"),
            true => Method::new("rsm-splat-restricted"),
        }
    }
    fn color(&self) -> [u8; 3] {
        match self.restricted {
            false => [140, 86, 75],
            true => [227, 119, 194],
        }
    }
    fn help(&self) -> &'static str {
        match self.restricted {
            false => "Each VPL splats a full-screen quad, additively.",
            true => "Each VPL splats a quad bounded to where it can exceed --splat-threshold.",
        }
    }
    fn reads_regular_vpls(&self) -> bool {
        true
    }
    fn reads_visibility(&self) -> bool {
        true
    }
    fn params(&self) -> &'static [&'static [&'static dyn AnyParam]] {
        match self.restricted {
            false => &[],
            true => &[RESTRICTED_PARAMS],
        }
    }
    /// Full-screen splats evaluate every VPL at every pixel; restricted ones
    /// fewer, uncounted.
    fn evaluations_per_pixel(&self, s: &RenderSettings) -> Option<u64> {
        (!self.restricted).then_some(RegularVpls::of(s).count as u64)
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        Ok(Box::new(RsmSplat::new(setup, self.restricted)?))
    }
}

/// Fails with a clear message when `format` cannot be blended into.
pub fn require_blending(gpu: &Gpu, format: vk::Format, method: &str) -> Result<()> {
    let blendable = vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND;
    if gpu.pick_format(&[format], blendable).is_none() {
        bail!(
            "{} cannot blend into {format:?} render targets, which method {method} splats into; choose another method",
            gpu.info.name
        );
    }
    Ok(())
}

pub struct RsmSplat {
    pipeline: PassPipeline,
    vpls: u32,
}

impl RsmSplat {
    /// `restricted`: quads bounded by `--splat-threshold` (else full screen).
    pub fn new(setup: &Setup, restricted: bool) -> Result<Self> {
        let format = setup.targets.indirect.format;
        let vpls = RegularVpls::of(setup.settings);
        // Read only when restricted.
        let threshold = match restricted {
            true => THRESHOLD.get(setup.settings),
            false => 0.0,
        };
        require_blending(setup.gpu, format, "rsm-splat")?;
        let pipeline = PassPipeline::graphics(
            setup.gpu,
            setup.frame,
            &full_resolution_bindings(setup),
            GraphicsDesc {
                name: "rsm-splat",
                vertex_shader: "rsm_splat/splat.vert",
                fragment_shader: "rsm_splat/splat.frag",
                color_formats: &[format],
                blend: Blend::Additive,
                specialization: &[
                    &[
                        Spec::bool("RESTRICTED", restricted),
                        Spec::float("SPLAT_THRESHOLD", threshold),
                    ],
                    &crate::visibility::specialization(setup.settings)[..],
                    &vpls.specialization(setup.settings),
                ]
                .concat(),
                ..Default::default()
            },
        )?;
        Ok(Self {
            pipeline,
            vpls: vpls.count,
        })
    }
}

impl IndirectMethod for RsmSplat {
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, _: usize) {
        let (gpu, cmd, indirect) = (ctx.gpu, ctx.cmd, &ctx.targets.indirect);
        profiler.pass(gpu, cmd, "rsm-splat", INDIRECT_GRAPHICS, || unsafe {
            barrier::transition(
                gpu,
                cmd,
                &[indirect],
                Use::DISCARD_AFTER_READERS,
                Use::COLOR_ATTACHMENT,
            );
            // Cleared to zero by the load op, then every splat adds.
            begin_rendering(
                gpu,
                cmd,
                &Attachments::simple(&[indirect.view], None, indirect.extent),
            );
            self.pipeline.bind(gpu, cmd, ctx.frame_set);
            gpu.device.cmd_draw(cmd, 6, self.vpls, 0, 0);
            gpu.device.cmd_end_rendering(cmd);
            barrier::transition(gpu, cmd, &[indirect], Use::COLOR_ATTACHMENT, Use::READ_ONLY);
        });
    }
}
