//! Indirect visibility (docs/algorithm.md sections 5.5 and 5.6): the
//! `--visibility` choice every gathering method reads, and what it puts into
//! their pipelines. `none` is the talk's model; `voxels` marches the segment
//! from receiver to light patch through this frame's voxel grid
//! (`voxel_grid`, `shaders/voxel_grid/march.glsl`), compiled into the patch
//! formula (`shaders/vpl.glsl`) by one specialization constant, its only way
//! to the GPU; `exact` is the dense reference's CPU limit
//! (`exact_visibility`).

use crate::settings::params::{AnyParam, Choices, DefaultValue, Param, Range};
use crate::settings::RenderSettings;
use crate::vk::pipeline::Spec;
use crate::voxel_grid;
use anyhow::{bail, Result};

/// Which light patches see which receivers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// Every patch lights every receiver it faces (the talk's model).
    None,
    /// One ray per receiver and VPL, on the CPU (`reference` only).
    Exact,
    /// The segment marched through this frame's voxel occupancy grid, on the GPU.
    Voxels,
}

impl Choices for Visibility {
    const NAMES: &'static [(&'static str, &'static str)] = &[
        (
            "none",
            "every light patch lights every receiver it faces, occluded or not (the talk's model)",
        ),
        (
            "exact",
            "--method reference only: a ray from each receiver to each VPL through the scene's \
             BVH, on the CPU (slow: the limit the model can reach)",
        ),
        (
            "voxels",
            "the segment from receiver to light patch marched through a voxel occupancy grid \
             of the posed scene, built on the GPU every frame (--visibility-grid)",
        ),
    ];
    fn index(self) -> usize {
        self as usize
    }
    fn from_index(i: usize) -> Self {
        [Visibility::None, Visibility::Exact, Visibility::Voxels][i]
    }
}

pub const VISIBILITY: Param<Visibility> = Param {
    name: "visibility",
    help: "Whether light patches are occluded on their way to a receiver: none, voxels (a \
           grid built every frame on the GPU), or exact (--method reference: the CPU limit, \
           minutes at 256x256)",
    // The default method's best balance needs the grid (docs/results.md,
    // "Best balance"): without it every gathering method is 5x or more
    // further from the truth.
    default: DefaultValue::Fixed(Visibility::Voxels),
    range: Range::ANY,
};

/// The parameters of every method that reads visibility: the choice and the
/// grid's.
pub const PARAMS: &[&dyn AnyParam] = &[&VISIBILITY, &voxel_grid::GRID, &voxel_grid::SUBCELLS];

/// Whether `s` asks for the voxel grid.
pub fn uses_voxels(s: &RenderSettings) -> bool {
    VISIBILITY.get(s) == Visibility::Voxels
}

/// The warning for the grid's parameters set where no run uses the grid
/// (`grid_used`: whether one does), which is most likely a forgotten
/// `--visibility voxels`.
pub fn unused_grid_warning(s: &RenderSettings, grid_used: bool) -> Option<String> {
    let set: Vec<String> = [&voxel_grid::GRID, &voxel_grid::SUBCELLS]
        .into_iter()
        .filter(|p| p.is_set_in(s))
        .map(|p| format!("--{} {}", p.name, p.get(s)))
        .collect();
    (!set.is_empty() && !grid_used).then(|| {
        let verb = if set.len() == 1 { "has" } else { "have" };
        format!(
            "warning: {} {verb} no effect without --visibility voxels",
            set.join(" and ")
        )
    })
}

/// The specialization constants of every pipeline that evaluates the patch
/// formula: `VOXEL_VISIBILITY` (`shaders/vpl.glsl`; the march is compiled
/// only into runs with the grid, as a uniform branch around it slowed every
/// gather on lavapipe) and the grid's layout (`voxel_grid::specialization`).
pub fn specialization(s: &RenderSettings) -> [Spec; 2] {
    [
        Spec::bool("VOXEL_VISIBILITY", uses_voxels(s)),
        voxel_grid::specialization(s),
    ]
}

/// Checks for a method that reads the visibility: `exact` is the CPU limit
/// of the dense reference only.
pub fn check(s: &RenderSettings, method: &str, reads_exact: bool) -> Result<()> {
    if VISIBILITY.get(s) == Visibility::Exact && !reads_exact {
        bail!(
            "--visibility exact is the CPU limit of --method reference only; --method {method} \
             takes --visibility none or voxels"
        );
    }
    Ok(())
}

/// Lavapipe ends all loops of a shader invocation after 65,535 iterations
/// together (gallivm's loop limiter), silently. A march through the grid
/// takes at most `VISIBILITY_MAX_ITERATIONS` (13,
/// `shaders/voxel_grid/march.glsl`) iterations, its evaluation one more of
/// the caller's loop and one to test the march's condition: this many per
/// evaluation.
pub const LOOP_ITERATIONS_PER_EVALUATION: u64 = 15;

/// What a fragment may spend on loops there, with room for its other loops.
pub const LOOP_BUDGET: u64 = 61_440;
