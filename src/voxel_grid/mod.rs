//! The voxel grid (docs/algorithm.md section 5.6, "Voxel visibility"): this
//! frame's posed scene voxelized on the GPU every frame, nothing kept across
//! frames. Methods read it for indirect visibility (`visibility`,
//! `shaders/voxel_grid/march.glsl`); it is declared here once: its
//! parameters, its layout and bytes, its cube around the scene, its buffers
//! ([`VoxelGrid`]) and the pass that fills them ([`VoxelizePass`]).
//!
//! What a cell holds today is occupancy: a bit per cell of every level and,
//! with sub-cells, a 64-bit mask per finest cell (`shaders/voxel_grid/
//! layout.glsl`), one storage buffer bound as set 0 binding 3 of every
//! pipeline (the frame set, `frame::FrameSet`). Attributes that further
//! passes need per cell (albedo, normal, surface area and centroid,
//! radiance, their mips) go beside it in [`VoxelGrid`] as buffers of their
//! own, counted in [`VoxelGrid::bytes`], filled by the same voxelization.
//! Its side and levels reach the shaders in the run uniforms
//! ([`write_uniforms`]), its sub-cells as one specialization constant
//! ([`specialization`]) and its cube in the frame uniforms ([`grid_cube`]).

use crate::gpu_types::RunUniforms;
use crate::settings::params::{DefaultValue, Param, Range};
use crate::settings::RenderSettings;
use crate::vk::pipeline::Spec;
use crate::vk::{Buffer, Gpu};
use anyhow::{bail, Result};
use ash::vk;
use glam::Vec3;
use gpu_allocator::MemoryLocation;

pub mod surface;
mod triangle_order;
mod voxelize;
pub use triangle_order::TriangleOrder;
pub use voxelize::{rows_per_triangle, VoxelizePass};

/// The finest cells per side of the voxel grid.
pub const GRID: Param<u32> = Param {
    name: "visibility-grid",
    help: "--visibility voxels: finest cells per side of the occupancy grid, a power of 2 \
           (the grid is a cube around the posed scene)",
    default: DefaultValue::Fixed(64),
    range: Range::powers_of(2, 16.0, 1024.0),
};

/// Sub-cells per side of a finest cell.
pub const SUBCELLS: Param<u32> = Param {
    name: "visibility-subcells",
    help: "--visibility voxels: sub-cells per side of each finest cell of the grid (1, 2 or \
           4): occupancy kept at that finer scale, so thin occluders cast shadows no wider \
           than they are and the march starts nearer the receiver; 1 is the plain grid \
           (faster, 1 bit a cell against 8 bytes)",
    default: DefaultValue::Fixed(4),
    range: Range::powers_of(2, 1.0, 4.0),
};

/// The coarsest level has 4 x 4 x 4 cells (whole 32-bit words, and coarser
/// levels would be occupied almost always).
const COARSEST_SIDE: u32 = 4;

/// Levels of a grid of side `n`: n, n/2, ..., 4.
pub fn levels(n: u32) -> u32 {
    n.ilog2() - COARSEST_SIDE.ilog2() + 1
}

/// The grid's specialization constant: `GRID_SUB`, its sub-cells per side
/// of a finest cell (`shaders/voxel_grid/layout.glsl`: the layout, and the
/// march's sub-cell samples).
pub fn specialization(s: &RenderSettings) -> Spec {
    Spec::int("GRID_SUB", SUBCELLS.get(s) as i32)
}

/// Bytes of the grid of `s`.
pub fn bytes(s: &RenderSettings) -> u64 {
    grid_bytes(GRID.get(s), SUBCELLS.get(s))
}

/// Bytes of a grid of side `n` with `sub` sub-cells per side of a finest
/// cell (`shaders/voxel_grid/layout.glsl`): a bit per cell of every OR-level,
/// about n^3 / 56 bytes, and a bit (`sub` 1) or a 64-bit mask of its
/// sub-cells (2, 4) per finest cell.
pub fn grid_bytes(n: u32, sub: u32) -> u64 {
    let finest = match sub {
        1 => (n as u64).pow(3) / 8,
        _ => 8 * (n as u64).pow(3),
    };
    finest
        + (1..levels(n))
            .map(|k| (n as u64 >> k).pow(3) / 8)
            .sum::<u64>()
}

/// Checks, before anything is allocated, that the grid of `s` fits the one
/// storage buffer `gpu` binds it as: with 4 sub-cells at 256 it takes 129
/// MiB (without, at 1024, 147 MiB), past the 128 MiB that some devices
/// (lavapipe among them) bind at once.
pub fn check_device(gpu: &Gpu, s: &RenderSettings) -> Result<()> {
    let (bytes, range) = (bytes(s), gpu.limits().max_storage_buffer_range as u64);
    if bytes > range {
        let (mut fits, sub) = (GRID.get(s), SUBCELLS.get(s));
        while fits > 16 && grid_bytes(fits, sub) > range {
            fits /= 2;
        }
        bail!(
            "--visibility-grid {} --visibility-subcells {sub}: the grid takes {} MiB, more \
             than {} binds in one buffer (maxStorageBufferRange: {} MiB); choose \
             --visibility-grid {fits} or less",
            GRID.get(s),
            bytes.div_ceil(1 << 20),
            gpu.info.name,
            range >> 20
        );
    }
    Ok(())
}

/// The grid's fields of the run uniforms: its side and levels.
pub fn write_uniforms(s: &RenderSettings, u: &mut RunUniforms) {
    let n = GRID.get(s);
    u.grid_side = n as i32;
    u.grid_levels = levels(n) as i32;
}

/// The grid's cube for a posed scene whose instances have the world boxes
/// `boxes`: centred on their union, its side the union's largest extent and
/// a margin of one and a half cells more on each side, `n` cells per side.
/// Surfaces on the bounds then lie inside cells, along the largest extent in
/// their middle: a plane on a face between two cells would make both
/// occupied. With `sub` sub-cells (2, 4) the middle of a cell is a face
/// between sub-cells, so the margin is half a sub-cell more, which puts those
/// surfaces in the middle of a sub-cell instead (one layer of sub-cells, not
/// two). xyz: its min corner; w: a cell's side.
pub fn grid_cube(boxes: impl Iterator<Item = (Vec3, Vec3)>, n: u32, sub: u32) -> [f32; 4] {
    let (lo, hi) = boxes
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
        .unwrap_or((Vec3::ZERO, Vec3::ZERO));
    let extent = (hi - lo).max_element().max(1e-6);
    let margin = match sub {
        1 => 1.5,
        _ => 1.5 + 0.5 / sub as f32,
    };
    let cell = extent / (n as f32 - 2.0 * margin);
    let side = cell * n as f32;
    let corner = (lo + hi) * 0.5 - Vec3::splat(side * 0.5);
    [corner.x, corner.y, corner.z, cell]
}

/// The grid of a run: its buffers, bound in every frame set (set 0 binding
/// 3), made whether or not a pass reads them (a 16-byte stand-in where none
/// does), so one frame-set layout serves every pipeline.
pub struct VoxelGrid {
    /// Occupancy: a bit per cell of every level, and a mask of sub-cells per
    /// finest cell with `--visibility-subcells` 2 or 4.
    pub occupancy: Buffer,
    /// The surface inside each finest cell (`surface`), for the passes that
    /// read it.
    pub surface: Option<Buffer>,
}

/// What a run asks of the grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Contents {
    /// Occupancy, for visibility.
    pub occupancy: bool,
    /// The surface inside each cell (`surface`).
    pub surface: bool,
}

impl Contents {
    pub fn any(self) -> bool {
        self.occupancy || self.surface
    }
}

impl VoxelGrid {
    /// The grid of `s` with `contents`; occupancy is a 16-byte stand-in
    /// when nothing reads the grid (the frame set binds it always).
    pub fn new(gpu: &Gpu, s: &RenderSettings, contents: Contents) -> Result<Self> {
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::TRANSFER_DST
            | vk::BufferUsageFlags::TRANSFER_SRC;
        let occupancy = Buffer::new(
            gpu,
            "voxel grid occupancy",
            if contents.any() { bytes(s) } else { 16 },
            usage,
            MemoryLocation::GpuOnly,
        )?;
        let surface = match contents.surface {
            true => Some(Buffer::new(
                gpu,
                "voxel grid surface",
                surface::bytes(s),
                usage,
                MemoryLocation::GpuOnly,
            )?),
            false => None,
        };
        Ok(Self { occupancy, surface })
    }

    /// Bytes of every buffer of the grid of `s` with `contents` (the memory
    /// check's count, before anything is allocated).
    pub fn bytes(s: &RenderSettings, contents: Contents) -> u64 {
        let occupancy = if contents.any() { bytes(s) } else { 0 };
        let surface = if contents.surface {
            surface::bytes(s)
        } else {
            0
        };
        occupancy + surface
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_and_bytes() {
        assert_eq!(levels(16), 3);
        assert_eq!(levels(64), 5);
        // 64^3 / 8 + 32^3 / 8 + 16^3 / 8 + 8^3 / 8 + 4^3 / 8 bytes.
        assert_eq!(grid_bytes(64, 1), 32768 + 4096 + 512 + 64 + 8);
        // With sub-cells, 8 bytes per finest cell.
        assert_eq!(grid_bytes(64, 4), 8 * 262_144 + 4096 + 512 + 64 + 8);
        assert_eq!(grid_bytes(64, 2), grid_bytes(64, 4));
        // The shader's offset formula: words before level k are (n^3 - m^3) / 28.
        for n in [16u64, 64, 1024] {
            let mut words = 0;
            for k in 0..levels(n as u32) {
                let m = n >> k;
                assert_eq!(words, (n * n * n - m * m * m) / 28, "{n} {k}");
                words += m * m * m / 32;
            }
            assert_eq!(words * 4, grid_bytes(n as u32, 1));
            // With sub-cells: level 0's masks, 2 n^3 words, then the same
            // levels of bits from level 1: before level k, 2 n^3 +
            // ((n / 2)^3 - m^3) / 28, every level at an even word.
            let (h, mut words) = (n / 2, 2 * n * n * n);
            for k in 1..levels(n as u32) {
                let m = n >> k;
                assert_eq!(
                    words,
                    2 * n * n * n + (h * h * h - m * m * m) / 28,
                    "{n} {k}"
                );
                assert_eq!(words % 2, 0);
                words += m * m * m / 32;
            }
            assert_eq!(words * 4, grid_bytes(n as u32, 4));
        }
    }

    #[test]
    fn the_cube_holds_the_boxes_with_a_cell_to_spare() {
        let boxes = [
            (Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 2.0, 1.0)),
            (Vec3::new(-1.0, 0.5, 0.0), Vec3::new(0.0, 1.0, 3.0)),
        ];
        let [x, y, z, cell] = grid_cube(boxes.into_iter(), 64, 1);
        let lo = Vec3::new(x, y, z);
        let hi = lo + Vec3::splat(cell * 64.0);
        assert!((cell - 3.0 / 61.0).abs() < 1e-6);
        assert!(lo.cmple(Vec3::new(-1.0, 0.0, 0.0) - cell * 1.49).all());
        assert!(hi.cmpge(Vec3::new(1.0, 2.0, 3.0) + cell * 1.49).all());
        // With 4 sub-cells the bounds of the largest extent (z, 3 long) lie
        // in the middle of a sub-cell: 1.625 cells, 6.5 sub-cells, in.
        let [_, _, z, cell] = grid_cube(boxes.into_iter(), 64, 4);
        assert!((cell - 3.0 / 60.75).abs() < 1e-6);
        let inside = |p: f32| (p - z) / cell * 4.0;
        assert!((inside(0.0) - 6.5).abs() < 1e-3 && (inside(3.0) - (256.0 - 6.5)).abs() < 1e-3);
    }
}
