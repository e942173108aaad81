//! Method `lpv`: Cascaded Light Propagation Volumes (Kaplanyan & Dachsbacher,
//! I3D 2010; docs/algorithm.md section 8), on the same RSM, G-buffer and
//! composite as every other method. Per light view: the RSM's VPLs are
//! injected into nested grids around the camera as 2-band SH intensities
//! (`lpv-inject`), propagated to their six neighbours `--lpv-iterations`
//! times past a geometry volume of blocking potentials (`lpv-propagate`;
//! the volume from the RSM in `lpv-inject`, from the G-buffer once per frame
//! in `lpv-geometry`), and every pixel reads irradiance from the finest
//! cascade that holds it (`lpv-lookup`). Nothing is kept between frames.
//!
//! This module declares the method and its parameters; `volume` makes and
//! records its passes; `grid` is the host's copy of the layout, the
//! placement and the lookup (what tests compare the GPU with).

pub mod grid;
pub mod volume;

use super::{Descriptor, IndirectMethod};
use crate::frame::Setup;
use crate::settings::params::{AnyParam, DefaultValue, Param, Range};
use crate::settings::{Method, Params, RenderSettings};
use anyhow::{bail, Result};

pub use volume::Lpv;

pub const KEY: Method = Method::new("lpv");

pub const SIZE: Param<u32> = Param {
    name: "lpv-size",
    help: "LPV: cells per side of each cascade",
    default: DefaultValue::Fixed(DEFAULT_SIZE),
    range: Range::powers_of(2, 8.0, 64.0),
};

pub const CASCADES: Param<u32> = Param {
    name: "lpv-cascades",
    help: "LPV: nested grids, each twice the side of the one inside it; the coarsest holds \
           the scene's bounds, the finer ones lie around the camera",
    default: DefaultValue::Fixed(DEFAULT_CASCADES),
    range: Range::closed(1.0, 4.0),
};

pub const ITERATIONS: Param<u32> = Param {
    name: "lpv-iterations",
    help: "LPV: propagation steps; light travels one cell of each cascade per step",
    default: DefaultValue::Derived(|s| SIZE.get(s), "--lpv-size, once across a cascade"),
    range: Range::closed(0.0, 64.0),
};

pub const OCCLUSION: Param<bool> = Param {
    name: "lpv-occlusion",
    help: "LPV: blocking potentials from the RSM's and the G-buffer's surfels (the \
           geometry volume) attenuate propagation",
    default: DefaultValue::Fixed(true),
    range: Range::ANY,
};

pub const PARAMS: &[&dyn AnyParam] = &[&SIZE, &CASCADES, &ITERATIONS, &OCCLUSION];

/// The default grid, chosen against the one-bounce truth (docs/algorithm.md
/// section 8.1, `examples/lpv_energy.rs`): with as many steps as cells, the
/// light LPV spreads along lit floors (the 2-band lobe sends a quarter of
/// its peak sideways) and its diffusion keep light longer than it travels,
/// both growing with the steps, so finer grids put more light on the image
/// than the truth has; the 8-cell grid is the one that keeps every bench
/// scene and the bunny room within a factor of 2.
pub const DEFAULT_SIZE: u32 = 8;
pub const DEFAULT_CASCADES: u32 = 1;

/// What a run of `s` builds: the derived sizes, from the one place they are
/// derived.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Cells per side of a cascade.
    pub size: u32,
    pub cascades: u32,
    pub iterations: u32,
    pub occlusion: bool,
    /// The RSM quadtree level injected as VPLs (and as the RSM's surfels):
    /// the level with at most 4 texels per cell side of a cascade's side,
    /// `log2(R / min(R, 4 size))`, so that the VPLs' density follows the grid
    /// rather than the RSM (the paper injects a reduced RSM too).
    pub vpl_level: u32,
    /// G-buffer pixels per side of one geometry surfel: one in each block,
    /// standing for the block, about 4 per cell side across the image,
    /// `max(1, min(W, H) / (4 size))`.
    pub gbuffer_stride: u32,
}

impl Layout {
    pub fn of(s: &RenderSettings) -> Self {
        let size = SIZE.get(s);
        let r = s.rsm_resolution;
        Self {
            size,
            cascades: CASCADES.get(s),
            iterations: ITERATIONS.get(s),
            occlusion: OCCLUSION.get(s),
            vpl_level: r.ilog2() - r.min(4 * size).ilog2(),
            gbuffer_stride: (s.width.min(s.height) / (4 * size)).max(1),
        }
    }

    /// Cells over which the lookup hands a cascade over to the next coarser
    /// one near its border (`BLEND` in `shaders/lpv/lookup.frag`): an eighth
    /// of the side, at least 1.
    pub fn blend_cells(&self) -> u32 {
        (self.size / 8).max(1)
    }

    /// Cells of all cascades.
    pub fn cells(&self) -> u64 {
        (self.size as u64).pow(3) * self.cascades as u64
    }

    /// VPLs (and RSM surfels) per side.
    pub fn vpl_side(&self, rsm_resolution: u32) -> u32 {
        rsm_resolution >> self.vpl_level
    }

    /// Geometry surfels taken from the G-buffer of a `width` x `height` image.
    pub fn gbuffer_surfels(&self, width: u32, height: u32) -> u32 {
        width.div_ceil(self.gbuffer_stride) * height.div_ceil(self.gbuffer_stride)
    }

    /// Bytes of GPU memory: the three injection images (RGBA32F), three
    /// buffers of three SH planes (RGBA32F: the two iterations in flight and
    /// their sum) and, with occlusion, the two geometry volumes (RGBA32F)
    /// and their copy as a buffer.
    pub fn bytes(&self) -> u64 {
        let cells = self.cells();
        let geometry = if self.occlusion { 2 * 16 + 2 * 16 } else { 0 };
        cells * (3 * 16 + 3 * 3 * 16 + geometry)
    }
}

pub struct LpvMethod;

impl Descriptor for LpvMethod {
    fn key(&self) -> Method {
        KEY
    }
    fn color(&self) -> [u8; 3] {
        [23, 190, 207]
    }
    fn help(&self) -> &'static str {
        "Cascaded light propagation volumes: VPLs in SH grids, propagated to neighbours."
    }
    fn params(&self) -> &'static [&'static [&'static dyn AnyParam]] {
        &[PARAMS]
    }
    fn check(&self, s: &RenderSettings) -> Result<()> {
        let (n, steps) = (SIZE.get(s), ITERATIONS.get(s));
        // The longest path between two cells of a cascade is 3 (N - 1) steps.
        if steps > 3 * (n - 1) {
            bail!(
                "--lpv-iterations {steps} with --lpv-size {n}: light crosses a cascade in at \
                 most {} steps, so more change nothing",
                3 * (n - 1)
            );
        }
        Ok(())
    }
    fn memory(&self, s: &RenderSettings) -> u64 {
        Layout::of(s).bytes()
    }
    fn sweep(&self, _rsm: u32, quick: bool) -> Vec<Params> {
        sweep(quick)
    }
    fn label(&self, s: &RenderSettings) -> String {
        let l = Layout::of(s);
        let mut label = format!("{}^3 x {}, {} steps", l.size, l.cascades, l.iterations);
        if !l.occlusion {
            label += ", no occlusion";
        }
        label
    }
    /// Propagation steps: how far light spreads, and what it costs.
    fn main_param(&self) -> Option<&'static dyn AnyParam> {
        Some(&ITERATIONS)
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        Ok(Box::new(Lpv::new(setup)?))
    }
}

/// LPV's points in the bench: every grid size (8 to 64 cells) at its
/// default steps (as many as cells), so that the chart shows how far a
/// finer grid gets; the default grid at half and twice the steps; 16 and 32
/// cells in three cascades (the finer ones around the camera); occlusion
/// off. Quick: the default, 16 cells and occlusion off.
fn sweep(quick: bool) -> Vec<Params> {
    let cells = |n: u32| Params::new().with(&SIZE, n);
    let mut v = vec![
        Params::new(),
        cells(2 * DEFAULT_SIZE),
        Params::new().with(&OCCLUSION, false),
    ];
    if !quick {
        v.push(cells(4 * DEFAULT_SIZE));
        v.push(cells(8 * DEFAULT_SIZE));
        v.push(Params::new().with(&ITERATIONS, DEFAULT_SIZE / 2));
        v.push(Params::new().with(&ITERATIONS, 2 * DEFAULT_SIZE));
        for n in [16, 32] {
            v.push(cells(n).with(&CASCADES, 3));
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_follows_the_settings() {
        let s = RenderSettings {
            width: 256,
            height: 128,
            rsm_resolution: 512,
            ..RenderSettings::DEFAULT
        }
        .with_method(KEY);
        let l = Layout::of(&s);
        assert_eq!(
            (l.size, l.cascades, l.iterations, l.occlusion),
            (DEFAULT_SIZE, DEFAULT_CASCADES, DEFAULT_SIZE, true)
        );
        // The steps follow the cells unless set.
        let s32 = s.clone().with(&SIZE, 32).with(&CASCADES, 3);
        let l = Layout::of(&s32);
        assert_eq!((l.size, l.iterations), (32, 32));
        assert_eq!(Layout::of(&s.clone().with(&ITERATIONS, 8)).iterations, 8);
        // 128 VPLs a side: level 2 of 512; 128 / 128 = 1 pixel per surfel.
        assert_eq!(
            (l.vpl_level, l.vpl_side(512), l.gbuffer_stride),
            (2, 128, 1)
        );
        assert_eq!(l.bytes(), 32 * 32 * 32 * 3 * (48 + 144 + 64));
        // 32 cells: an RSM of 64 is injected whole (4 x 32 >= 64); 8 cells
        // at their 32 texels a side take level 1.
        let small = |s: &RenderSettings| {
            Layout::of(&RenderSettings {
                rsm_resolution: 64,
                ..s.clone()
            })
            .vpl_level
        };
        assert_eq!((small(&s32), small(&s)), (0, 1));
        assert!(LpvMethod.check(&s).is_ok());
        assert!(LpvMethod
            .check(&s.clone().with(&ITERATIONS, 64).with(&SIZE, 8))
            .is_err());
    }
}
