//! Method `vct`: voxel cone tracing (Crassin et al., Pacific Graphics 2011;
//! docs/algorithm.md section 9), on the same RSM, G-buffer, voxel grid and
//! composite as every other method. Per light view: the RSM's texels inject
//! the direct light's outgoing radiance into the cells of the voxel grid
//! (`vct-inject`), a 3D image of premultiplied radiance and opacity and its
//! mips are built from it and from the surface area in each cell
//! (`vct-mips`, the grid's `voxel-surface` sums), and every pixel traces a
//! few wide cones through the mips (`vct-trace`). Nothing is kept between
//! frames.
//!
//! This module declares the method and its parameters; `volume` makes and
//! records its passes; `cones` is the host's copy of the cone set (what the
//! tests and the docs hold the shader to).

pub mod cones;
pub mod volume;

use super::{Descriptor, IndirectMethod};
use crate::frame::Setup;
use crate::settings::params::{AnyParam, DefaultValue, Param, Range};
use crate::settings::{Method, Params, RenderSettings};
use crate::voxel_grid;
use anyhow::{bail, Result};

pub use volume::Vct;

pub const KEY: Method = Method::new("vct");

pub const CONES: Param<u32> = Param {
    name: "vct-cones",
    help: "VCT: diffuse cones per pixel, one along the normal and the rest in a ring 60 \
           degrees off it (5 to 9)",
    default: DefaultValue::Fixed(6),
    range: Range::closed(5.0, 9.0),
};

pub const LOBE: Param<bool> = Param {
    name: "vct-lobe",
    help: "VCT: cells send light only to the side their lit surface faces (a mean normal \
           per cell and mip); off, every cell glows the same way in every direction",
    default: DefaultValue::Fixed(true),
    range: Range::ANY,
};

/// The grid side VCT takes at most: 128^3 cells of three RGBA32F volumes
/// and their mips, and the sums, are 177 MiB; 256^3 would be 1.4 GiB.
pub const MAX_SIDE: u32 = 128;

/// Its own parameters, and the grid's side (`--visibility-grid`), which it
/// reads too: its cells are the voxel grid's finest cells.
pub const PARAMS: &[&dyn AnyParam] = &[&voxel_grid::GRID, &CONES, &LOBE];

/// What a run of `s` builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Cells per side of the finest level (the voxel grid's).
    pub side: u32,
    /// Mip levels: side, side / 2, ..., 1.
    pub levels: u32,
    pub cones: u32,
    pub lobe: bool,
}

impl Layout {
    pub fn of(s: &RenderSettings) -> Self {
        let side = voxel_grid::GRID.get(s);
        Self {
            side,
            levels: side.ilog2() + 1,
            cones: CONES.get(s),
            lobe: LOBE.get(s),
        }
    }

    /// Cells of the finest level.
    pub fn cells(&self) -> u64 {
        (self.side as u64).pow(3)
    }

    /// Bytes of GPU memory: the injection sums (8 words a cell) and three
    /// RGBA32F volumes (radiance and opacity; the lit surface's lobe; the
    /// surface's lobe) with their mips (each level an eighth of the one
    /// below: at most 8/7 of the finest).
    pub fn bytes(&self) -> u64 {
        let mips: u64 = (0..self.levels)
            .map(|k| (self.side as u64 >> k).pow(3))
            .sum();
        self.cells() * volume::ACCUM_WORDS as u64 * 4 + 3 * 16 * mips
    }
}

pub struct VctMethod;

impl Descriptor for VctMethod {
    fn key(&self) -> Method {
        KEY
    }
    fn color(&self) -> [u8; 3] {
        [214, 39, 40]
    }
    fn help(&self) -> &'static str {
        "Voxel cone tracing: RSM light injected into the voxel grid, mipped, gathered by cones."
    }
    fn params(&self) -> &'static [&'static [&'static dyn AnyParam]] {
        &[PARAMS]
    }
    fn reads_voxel_surface(&self, _s: &RenderSettings) -> bool {
        true
    }
    fn check(&self, s: &RenderSettings) -> Result<()> {
        let n = voxel_grid::GRID.get(s);
        if n > MAX_SIDE {
            bail!(
                "--visibility-grid {n} with --method vct: its radiance volumes take {} MiB; \
                 choose --visibility-grid {MAX_SIDE} or less",
                Layout::of(s).bytes() >> 20
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
        let mut label = format!("{}^3, {} cones", l.side, l.cones);
        if !l.lobe {
            label += ", isotropic";
        }
        label
    }
    /// The grid's side: how fine the light is carried, and what it costs.
    fn main_param(&self) -> Option<&'static dyn AnyParam> {
        Some(&voxel_grid::GRID)
    }
    fn create(&self, setup: &Setup) -> Result<Box<dyn IndirectMethod>> {
        Ok(Box::new(Vct::new(setup)?))
    }
}

/// VCT's points in the bench: the grid (32, 128) and the cones (5, 9) each
/// from the default (64^3, 6 cones), and the isotropic cells; quick: the
/// default, 32^3 and 9 cones.
fn sweep(quick: bool) -> Vec<Params> {
    let mut v = vec![
        Params::new(),
        Params::new().with(&voxel_grid::GRID, 32),
        Params::new().with(&CONES, 9),
    ];
    if !quick {
        v.push(Params::new().with(&voxel_grid::GRID, 128));
        v.push(Params::new().with(&CONES, 5));
        v.push(Params::new().with(&LOBE, false));
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_follows_the_settings() {
        let s = RenderSettings::DEFAULT.with_method(KEY);
        let l = Layout::of(&s);
        assert_eq!((l.side, l.levels, l.cones, l.lobe), (64, 7, 6, true));
        // 64^3 cells of 32 bytes, and three volumes of 16 bytes a texel over
        // 64^3 + 32^3 + ... + 1 texels.
        let mips: u64 = [64u64, 32, 16, 8, 4, 2, 1].iter().map(|n| n * n * n).sum();
        assert_eq!(l.bytes(), 262_144 * 32 + 48 * mips);
        assert!(VctMethod.check(&s).is_ok());
        assert!(VctMethod
            .check(&s.clone().with(&voxel_grid::GRID, 256))
            .is_err());
    }
}
