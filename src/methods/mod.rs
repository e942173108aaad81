//! Indirect-light methods, one module each (docs/algorithm.md sections 4 and
//! 5), and the registry that lists them. A method is one unit: its module
//! declares what it is (a [`Descriptor`]: name, help, parameters with their
//! ranges, capabilities, checks, GPU memory, uniforms, bench sweep) and
//! makes the object that records its passes (an [`IndirectMethod`]), which
//! writes the full-resolution indirect irradiance image `Targets::indirect`,
//! either through the multiresolution buffer (`multires::MultiresMethod`,
//! with a light-space source of its own, `multires::LightSource`) or
//! directly at full resolution.
//!
//! Adding a method: its module here (a `Descriptor` and its passes), its
//! shaders in a folder of their own (`shaders/<method>/`), and one line in
//! [`REGISTRY`] (with its `mod` line above). `settings::Method` is only its
//! key; the CLI, checks, viewer and bench read the rest from the registry,
//! and no shared module names it (`tests/house_rules.rs`).

pub mod hisr;
pub mod isr;
pub mod lpv;
pub mod multires_gather;
pub mod multires_splat;
pub mod none;
pub mod reference;
pub mod rsm_gather;
pub mod rsm_splat;
pub mod vct;

use crate::frame::{FrameContext, Setup};
use crate::gpu_types::RunUniforms;
use crate::multires::{self, LightPatches, MultiresBuffer, MultiresMethod};
use crate::regular_vpls;
use crate::settings::params::AnyParam;
use crate::settings::{Method, Params, RenderSettings};
use crate::vk::profiler::Profiler;
use crate::{visibility, voxel_grid};
use anyhow::{anyhow, bail, Result};

/// Every method, in the order of the CLI's help, the viewer's `M` key and
/// the bench's reports: the baselines, then the paper's methods, then the
/// reference. One line per method.
pub static REGISTRY: &[&dyn Descriptor] = &[
    &none::NoneMethod,
    &rsm_gather::RsmGatherMethod,
    &rsm_splat::RSM_SPLAT,
    &rsm_splat::RSM_SPLAT_RESTRICTED,
    &multires_splat::MultiresSplatMethod,
    &multires_gather::MultiresGatherMethod,
    &isr::IsrMethod,
    &hisr::HisrMethod,
    &lpv::LpvMethod,
    &vct::VctMethod,
    &reference::ReferenceMethod,
];

/// The method the bench measures the others against (its headline ratios:
/// speedups at equal error, its front): the paper's.
pub const SUBJECT: Method = hisr::KEY;

/// The dense reference: the converged limit the approximations are measured
/// against (method error), left out of the other methods' fronts.
pub const REFERENCE: Method = reference::KEY;

/// The method that adds no indirect light: direct light alone.
pub const DIRECT_ONLY: Method = none::KEY;

/// What a method is, before anything is made: everything the CLI, the
/// checks, the viewer and the bench need to know of it.
pub trait Descriptor: Sync {
    /// Its key (its CLI name).
    fn key(&self) -> Method;

    /// One sentence for `--help` and the README.
    fn help(&self) -> &'static str;

    /// The parameters it reads besides those its capabilities bring (below),
    /// in groups: each is a `--NAME` option and is checked against its range
    /// before a run.
    fn params(&self) -> &'static [&'static [&'static dyn AnyParam]] {
        &[]
    }

    /// Whether it works through the multiresolution buffer (its
    /// `IndirectMethod::multires` is then the buffer). The buffer's
    /// parameters, checks, memory and uniforms then come with it
    /// (`multires::PARAMS`, `multires::check`, ...).
    fn uses_multires(&self) -> bool {
        false
    }

    /// Whether it reads the N regular VPLs of `--vpls`: their parameters
    /// and check then come with it (`regular_vpls`), and its bench sweep
    /// and label default to the VPL count's.
    fn reads_regular_vpls(&self) -> bool {
        false
    }

    /// Whether it evaluates the patch formula (`patch_irradiance`,
    /// `shaders/vpl.glsl`) and so takes its visibility term:
    /// `--visibility` and `--visibility-grid` then come with it, the voxel
    /// grid's memory and uniforms too (`visibility`, `voxel_grid`).
    fn reads_visibility(&self) -> bool {
        false
    }

    /// Whether it reads the surface in the voxel grid's cells
    /// (`voxel_grid::surface`: area, albedo, normal, centroid), which pass
    /// `voxel-surface` then sums every frame (`Setup::grid_surface`).
    fn reads_voxel_surface(&self, _s: &RenderSettings) -> bool {
        false
    }

    /// Whether it takes bounces 2..N of `--bounces N` from the shared
    /// bounce passes (`bounce`), which add them to the indirect light it
    /// writes: every method that evaluates the patch formula (the
    /// gathering methods, the splats and the reference) by default.
    fn renders_bounces(&self) -> bool {
        self.reads_visibility()
    }

    /// Whether `--visibility exact` (the CPU limit) applies to it: the dense
    /// reference only.
    fn takes_exact_visibility(&self) -> bool {
        false
    }

    /// Whether the interactive viewer shows it: it renders a frame in one
    /// submission, in real time on a GPU.
    fn interactive(&self) -> bool {
        true
    }

    /// Checks across its own parameters and the sizes; each parameter's
    /// range and its capabilities' checks run before (`check`).
    fn check(&self, _s: &RenderSettings) -> Result<()> {
        Ok(())
    }

    /// Bytes of GPU memory its own resources take, besides its
    /// capabilities' (`memory`), for the check before anything is allocated.
    fn memory(&self, _s: &RenderSettings) -> u64 {
        0
    }

    /// Writes its own fields of the run uniforms (the shared ones and its
    /// capabilities' are written before, `write_uniforms`).
    fn write_uniforms(&self, _s: &RenderSettings, _u: &mut RunUniforms) {}

    /// The bench's sweep over its parameters for RSM resolution `rsm`: each
    /// point the values it sets; `quick` keeps two or three. Empty: the
    /// bench does not sweep it. One point sets nothing or only defaults.
    fn sweep(&self, rsm: u32, quick: bool) -> Vec<Params> {
        match self.reads_regular_vpls() {
            true => regular_vpls::sweep(rsm, quick),
            false => vec![],
        }
    }

    /// A short label for tables and charts: "256 VPLs", "tau 0.05, depth 6".
    fn label(&self, s: &RenderSettings) -> String {
        match self.reads_regular_vpls() {
            true => regular_vpls::label(s),
            false => self.key().name().into(),
        }
    }

    /// Its main knob: the parameter that trades its speed for accuracy,
    /// which `isr render -h` shows and the viewer's +/- keys scale. By
    /// default the VPL count for a method that reads regular VPLs.
    fn main_param(&self) -> Option<&'static dyn AnyParam> {
        self.reads_regular_vpls()
            .then_some(&regular_vpls::VPLS as &dyn AnyParam)
    }

    /// Warnings for settings that are valid but most likely not what was
    /// meant (options that have no effect in this combination).
    fn warnings(&self, _s: &RenderSettings) -> Vec<String> {
        vec![]
    }

    /// Its colour in the bench's charts (sRGB). By default one of a fixed
    /// palette, by its place in the registry.
    fn color(&self) -> [u8; 3] {
        const PALETTE: [[u8; 3]; 6] = [
            [148, 103, 189],
            [23, 190, 207],
            [188, 189, 34],
            [127, 127, 127],
            [255, 152, 150],
            [197, 176, 213],
        ];
        let i = REGISTRY
            .iter()
            .position(|d| d.key() == self.key())
            .unwrap_or(0);
        PALETTE[i % PALETTE.len()]
    }

    /// Light patches evaluated per pixel with geometry, where that is fixed
    /// (the full-resolution methods that evaluate every VPL everywhere);
    /// the multiresolution methods count theirs on the GPU.
    fn evaluations_per_pixel(&self, _s: &RenderSettings) -> Option<u64> {
        None
    }

    /// Makes it for a run.
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>>;
}

/// The descriptor of `m`.
pub fn find(m: Method) -> Result<&'static dyn Descriptor> {
    REGISTRY
        .iter()
        .copied()
        .find(|d| d.key() == m)
        .ok_or_else(|| {
            anyhow!(
                "unknown method '{m}'; the methods are: {}",
                names().join(", ")
            )
        })
}

/// The descriptor named `name` (the CLI's spelling).
pub fn by_name(name: &str) -> Result<&'static dyn Descriptor> {
    REGISTRY
        .iter()
        .copied()
        .find(|d| d.key().name() == name)
        .ok_or_else(|| {
            anyhow!(
                "unknown method '{name}'; the methods are: {}",
                names().join(", ")
            )
        })
}

/// Every method's name, in registry order.
pub fn names() -> Vec<&'static str> {
    REGISTRY.iter().map(|d| d.key().name()).collect()
}

/// Every parameter of `d`: its capabilities' (the multiresolution buffer's,
/// the regular VPLs'), then its own.
pub fn params_of(d: &dyn Descriptor) -> impl Iterator<Item = &'static dyn AnyParam> {
    let multires: &[&dyn AnyParam] = if d.uses_multires() {
        multires::PARAMS
    } else {
        &[]
    };
    let regular: &[&dyn AnyParam] = if d.reads_regular_vpls() {
        regular_vpls::PARAMS
    } else {
        &[]
    };
    let visibility: &[&dyn AnyParam] = if d.reads_visibility() {
        visibility::PARAMS
    } else {
        &[]
    };
    let bounces: &[&dyn AnyParam] = if d.renders_bounces() {
        &[&crate::bounces::BOUNCES, &crate::bounce::FEEDBACK]
    } else {
        &[]
    };
    let own = d.params().iter().flat_map(|g| g.iter().copied());
    multires
        .iter()
        .chain(regular)
        .chain(visibility)
        .chain(bounces)
        .copied()
        .chain(own)
}

/// Bytes of GPU memory `d`'s resources take for `s`, its capabilities' included.
pub fn memory(d: &dyn Descriptor, s: &RenderSettings) -> u64 {
    let multires = if d.uses_multires() {
        multires::memory(s)
    } else {
        0
    };
    // The grid is made for the run whenever `--visibility voxels` is set
    // (the viewer may switch to a method that reads it), so it counts
    // whatever the method.
    let grid = voxel_grid::VoxelGrid::bytes(s, grid_contents(d, s));
    let bounces = match renders_bounces(d, s) {
        true => crate::bounce::memory(s),
        false => 0,
    };
    multires + grid + bounces + d.memory(s)
}

/// What a run of `d` with `s` asks of the voxel grid: occupancy with
/// `--visibility voxels` (whatever the method: the viewer may switch to one
/// that reads it), the surface in its cells where `d` reads it.
pub fn grid_contents(d: &dyn Descriptor, s: &RenderSettings) -> voxel_grid::Contents {
    voxel_grid::Contents {
        occupancy: visibility::uses_voxels(s),
        surface: d.reads_voxel_surface(s) || renders_bounces(d, s),
    }
}

/// Whether a run of `d` with `s` records the bounce passes (`bounce`): `d`
/// takes them and `--bounces` asks for more than one.
pub fn renders_bounces(d: &dyn Descriptor, s: &RenderSettings) -> bool {
    d.renders_bounces() && crate::bounce::active(s)
}

/// Writes `d`'s fields of the run uniforms for `s`: its capabilities', then
/// its own.
pub fn write_uniforms(d: &dyn Descriptor, s: &RenderSettings, u: &mut RunUniforms) {
    if d.uses_multires() {
        multires::write_uniforms(s, u);
    }
    // The grid's side and levels: its passes run for any method that
    // reads it, by visibility or by its cells' surface.
    voxel_grid::write_uniforms(s, u);
    d.write_uniforms(s, u);
}

/// Parameters of a run that every command takes: `--bounces`, which the
/// path tracer, the bench's truth and the methods that `renders_bounces`
/// read (`bounces`). Set for a method that does not read it, it is warned
/// of as any parameter the method does not read (`unused_params`).
pub const RUN_PARAMS: &[&dyn AnyParam] = &[&crate::bounces::BOUNCES];

/// Every parameter of every method, once each, in registry order, then
/// those of [`RUN_PARAMS`] no method reads.
pub fn all_params() -> Vec<&'static dyn AnyParam> {
    let mut out: Vec<&'static dyn AnyParam> = vec![];
    let of_methods = REGISTRY.iter().flat_map(|&d| params_of(d));
    for p in of_methods.chain(RUN_PARAMS.iter().copied()) {
        if !out.iter().any(|q| q.name() == p.name()) {
            out.push(p);
        }
    }
    out
}

/// Checks `s` for its method: every parameter the method reads, and every
/// one `s` sets (a value out of range is wrong even where it has no
/// effect), against its range; then the method's own checks. Returns the
/// method's descriptor.
pub fn check(s: &RenderSettings) -> Result<&'static dyn Descriptor> {
    let d = find(s.method)?;
    for p in all_params() {
        if p.is_set_in(s) || params_of(d).any(|q| q.name() == p.name()) {
            p.check(s)?;
        }
    }
    if d.uses_multires() {
        multires::check(s, d.key().name())?;
    }
    if d.reads_regular_vpls() {
        regular_vpls::check(s)?;
    }
    if d.reads_visibility() {
        visibility::check(s, d.key().name(), d.takes_exact_visibility())?;
    }
    if d.renders_bounces() {
        crate::bounce::check(s)?;
    }
    d.check(s)?;
    Ok(d)
}

/// The parameters `s` sets that its method does not read (the CLI warns of
/// them: they have no effect).
pub fn unused_params(s: &RenderSettings) -> Vec<&'static str> {
    let Ok(d) = find(s.method) else {
        return vec![];
    };
    s.params
        .0
        .keys()
        .copied()
        .filter(|name| !params_of(d).any(|p| p.name() == *name))
        .collect()
}

/// Whether `s` holds its method's default values (of every parameter the
/// method reads) as `base` does: the bench's default point.
pub fn same_params(d: &dyn Descriptor, s: &RenderSettings, base: &RenderSettings) -> bool {
    params_of(d).all(|p| p.text_in(s) == p.text_in(base))
}

/// The object a method makes for a run: records its passes into every
/// frame after the RSM, G-buffer, direct light and (if it reads it) the RSM
/// quadtree, once per light view, and before the composite. Its GPU objects
/// free themselves when it is dropped.
pub trait IndirectMethod {
    /// Command buffers one frame of the method takes: the reference splits its
    /// work so that no submission runs long enough to trip a driver timeout.
    fn submissions(&self) -> usize {
        1
    }

    /// Records the passes that depend on the camera alone (the eye-space
    /// refinement), once per frame after the G-buffer: a frame with several
    /// light views (point-light faces, several lights) shares them.
    fn record_eye_space(&self, _ctx: &FrameContext, _profiler: &mut Profiler) {}

    /// Records submission `submission` (of `submissions()`) of one light view
    /// into `ctx.cmd`. After the last one, `indirect` is written and in the
    /// `READ_ONLY` state.
    fn record(&self, ctx: &FrameContext, profiler: &mut Profiler, submission: usize);

    /// Whether the frame must build the RSM quadtree (`passes::rsm_tree`) first.
    fn reads_rsm_tree(&self) -> bool {
        true
    }

    /// The multiresolution buffer, for the methods that fill one.
    fn multires(&self) -> Option<&MultiresBuffer> {
        None
    }

    /// The light patches its light-space source offered the gather in the
    /// last frame, for the methods that have one (a list, or a packed tree).
    fn light_patches(&self) -> Option<LightPatches<'_>> {
        None
    }
}

/// Every method that works through the multiresolution buffer is one.
impl IndirectMethod for MultiresMethod {
    fn record_eye_space(&self, ctx: &FrameContext, p: &mut Profiler) {
        MultiresMethod::record_eye_space(self, ctx, p);
    }

    fn record(&self, ctx: &FrameContext, p: &mut Profiler, _: usize) {
        MultiresMethod::record(self, ctx, p);
    }

    fn multires(&self) -> Option<&MultiresBuffer> {
        Some(self.buffer())
    }

    fn light_patches(&self) -> Option<LightPatches<'_>> {
        MultiresMethod::light_patches(self)
    }
}

/// The method `setup.settings.method` names, made for `setup`.
pub fn create(setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
    let d = find(setup.settings.method)?;
    let method = d.create(setup)?;
    if method.multires().is_some() != d.uses_multires() {
        bail!(
            "method {} says it {} the multiresolution buffer, but its object {}",
            d.key(),
            if d.uses_multires() {
                "uses"
            } else {
                "does not use"
            },
            if d.uses_multires() {
                "has none"
            } else {
                "has one"
            }
        );
    }
    Ok(method)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_the_default_is_registered() {
        let mut n = names();
        n.sort();
        n.dedup();
        assert_eq!(n.len(), REGISTRY.len());
        assert!(find(RenderSettings::DEFAULT.method).is_ok());
        assert!(by_name("pathtrace").is_err());
    }

    #[test]
    fn parameters_with_one_name_are_one_parameter() {
        // Two methods listing a parameter of the same name must list the
        // same declaration (one range, one default).
        let all = all_params();
        for &d in REGISTRY {
            for p in params_of(d) {
                let q = all.iter().find(|q| q.name() == p.name()).unwrap();
                assert!(
                    std::ptr::addr_eq(*q as *const dyn AnyParam, p as *const dyn AnyParam)
                        || (q.range() == p.range() && q.help() == p.help()),
                    "two declarations of --{}",
                    p.name()
                );
            }
        }
    }

    #[test]
    fn every_sweep_holds_its_default_once_and_only_valid_points() {
        let base = RenderSettings {
            rsm_resolution: 128,
            ..RenderSettings::DEFAULT
        };
        for &d in REGISTRY {
            for quick in [false, true] {
                let points = d.sweep(128, quick);
                let mut defaults = 0;
                for p in &points {
                    let mut s = base.clone().with_method(d.key());
                    s.params.overlay(p);
                    for q in params_of(d) {
                        q.check(&s).unwrap();
                    }
                    defaults += same_params(d, &s, &base.clone().with_method(d.key())) as usize;
                }
                if !points.is_empty() {
                    assert_eq!(defaults, 1, "{} quick={quick}", d.key());
                }
            }
        }
    }
}
