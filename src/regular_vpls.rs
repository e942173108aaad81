//! The N regular VPLs that the methods with a fixed VPL budget read
//! (docs/algorithm.md section 4.1), each method saying so with
//! `Descriptor::reads_regular_vpls`: level `log2(R / sqrt(N))` of the RSM
//! quadtree, each VPL its patch's summed flux and area at its mean position
//! and normal, or its centre texel (`--vpl-sampling point`). Their
//! parameters, the one function that derives their side and level
//! ([`RegularVpls`]), the specialization constants that carry them to
//! `shaders/regular_vpls/regular_vpls.glsl`, the light-space source that
//! lists them for the multiresolution gather ([`RegularVpls::list`]), and
//! the bench's VPL-count sweep.

use crate::frame::Setup;
use crate::multires::PatchList;
use crate::settings::params::{AnyParam, Choices, DefaultValue, Param, Range};
use crate::settings::{Params, RenderSettings};
use crate::vk::pipeline::Spec;
use anyhow::{bail, Result};
use ash::vk;

/// The largest `--vpls`: every texel of a 4096 x 4096 RSM.
const MAX_VPLS: f64 = 4096.0 * 4096.0;

pub const VPLS: Param<u32> = Param {
    name: "vpls",
    help: "Regular VPLs, a power of 4: the sqrt(N) x sqrt(N) level of the RSM quadtree",
    default: DefaultValue::Fixed(256),
    range: Range::powers_of(4, 1.0, MAX_VPLS),
};

/// How a regular VPL stands for its RSM patch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VplSampling {
    /// The patch's mean position and normal, summed flux and area.
    Mean,
    /// The texel at the patch centre, flux and area scaled by the texel count.
    Point,
}

impl Choices for VplSampling {
    const NAMES: &'static [(&'static str, &'static str)] = &[
        (
            "mean",
            "the patch's mean position and normal, summed flux and area",
        ),
        (
            "point",
            "the texel at the patch centre, flux and area scaled by the texel count",
        ),
    ];
    fn index(self) -> usize {
        self as usize
    }
    fn from_index(i: usize) -> Self {
        [VplSampling::Mean, VplSampling::Point][i]
    }
}

pub const VPL_SAMPLING: Param<VplSampling> = Param {
    name: "vpl-sampling",
    help: "A regular VPL is its patch's mean, or the patch's centre texel with scaled flux",
    default: DefaultValue::Fixed(VplSampling::Mean),
    range: Range::ANY,
};

pub const PARAMS: &[&dyn AnyParam] =
    &[&VPLS, &VPL_SAMPLING, &crate::passes::rsm_tree::PATCH_KERNEL];

/// The regular VPLs of a run: how many, how many per side, and the RSM
/// quadtree level they are. The host's draw counts and dispatch sizes and
/// the shaders' `VPL_SIDE` and `VPL_LEVEL` all come from here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegularVpls {
    pub count: u32,
    pub side: u32,
    pub level: u32,
}

impl RegularVpls {
    /// The `--vpls` of `s`.
    pub fn of(s: &RenderSettings) -> Self {
        Self::with_count(s, VPLS.get(s))
    }

    /// Every RSM texel (the dense reference).
    pub fn every_texel(s: &RenderSettings) -> Self {
        Self::with_count(s, s.rsm_resolution * s.rsm_resolution)
    }

    pub fn with_count(s: &RenderSettings, count: u32) -> Self {
        let side = ((count as f64).sqrt() as u32).max(1);
        let level = s.rsm_resolution.max(side).ilog2() - side.ilog2();
        Self { count, side, level }
    }

    /// The specialization constants of every shader that includes
    /// `shaders/regular_vpls/regular_vpls.glsl`: their level and side, and
    /// `--vpl-sampling`.
    pub fn specialization(&self, s: &RenderSettings) -> [Spec; 3] {
        [
            Spec::int("VPL_LEVEL", self.level as i32),
            Spec::int("VPL_SIDE", self.side as i32),
            Spec::bool("POINT_VPLS", VPL_SAMPLING.get(s) == VplSampling::Point),
        ]
    }

    /// The light-space source that writes them into one list once per
    /// frame, VPL j at entry j (pass `vpl-list`,
    /// `shaders/regular_vpls/list.comp`), for the multiresolution gather.
    pub fn list(&self, setup: &Setup) -> Result<PatchList> {
        PatchList::new(
            setup,
            (
                "vpl-list",
                "regular_vpls/list.comp",
                &self.specialization(setup.settings),
            ),
            false,
            self.count as u64,
            vk::Extent2D {
                width: self.side,
                height: self.side,
            },
        )
    }
}

/// `--vpls` against the RSM (after its own range).
pub fn check(s: &RenderSettings) -> Result<()> {
    let v = RegularVpls::of(s);
    let r = s.rsm_resolution;
    if v.side > r {
        bail!(
            "--vpls {} needs more RSM texels than --rsm {r} has ({} at most)",
            v.count,
            r as u64 * r as u64
        );
    }
    Ok(())
}

/// `label` of a method whose sweep is the VPL count.
pub fn label(s: &RenderSettings) -> String {
    format!("{} VPLs", VPLS.get(s))
}

/// The bench's sweep of the methods that take N regular VPLs: 64 to 4096
/// (quick: 64 and 256), capped by what the RSM holds.
pub fn sweep(rsm: u32, quick: bool) -> Vec<Params> {
    let counts: &[u32] = if quick {
        &[64, 256]
    } else {
        &[64, 256, 1024, 4096]
    };
    counts
        .iter()
        .filter(|&&n| n as u64 <= rsm as u64 * rsm as u64)
        .map(|&n| Params::new().with(&VPLS, n))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_and_level() {
        let s = RenderSettings {
            rsm_resolution: 256,
            ..RenderSettings::DEFAULT
        };
        assert_eq!(
            RegularVpls::of(&s),
            RegularVpls {
                count: 256,
                side: 16,
                level: 4
            }
        );
        let every = RegularVpls::every_texel(&s);
        assert_eq!((every.count, every.side, every.level), (65536, 256, 0));
    }

    #[test]
    fn counts_are_capped_by_the_rsm() {
        let counts: Vec<u32> = sweep(16, false)
            .iter()
            .map(|p| match p.get("vpls") {
                Some(crate::settings::Value::Count(n)) => n as u32,
                _ => unreachable!(),
            })
            .collect();
        assert_eq!(counts, [64, 256]);
    }
}
