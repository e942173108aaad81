//! Indirect visibility (issue 25; docs/algorithm.md section 5, "Exact indirect
//! visibility" and "Voxel visibility"): the parameters every gathering method
//! reads (`--visibility`, `--visibility-grid`), and pass `visibility-grid`,
//! which builds the voxel occupancy grid of this frame's posed scene.
//!
//! The grid is one storage buffer, set 0 binding 3 of every pipeline (the
//! frame set, `frame::FrameSet`): `shaders/voxel_grid/voxelize.comp` and
//! `shaders/voxel_grid/levels.comp` write it,
//! the patch formula (`patch_irradiance`, `shaders/vpl.glsl`) of every
//! gathering method reads it through `shaders/voxel_grid/march.glsl`. Nothing is
//! kept across frames: the pass clears it, voxelizes every instance's
//! triangles, posed by this frame's transforms, into the finest level of the
//! cube [`grid_cube`] puts around them (the large triangles by whole
//! workgroups, the rest one per invocation: [`TriangleOrder`]), then makes
//! each coarser level the OR of the one below it
//! (`shaders/voxel_grid/levels.comp`).
//!
//! Barriers (in `record`): the previous frame's readers (shaders of every
//! stage, the readback copy) before the clear; the clear before the
//! voxelization's atomics (none between its dispatches: they only OR bits
//! in); the atomics before the first OR-level, each OR-level before the
//! next; the last before every later reader.

use super::INDIRECT_COMPUTE;
use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{self, RunUniforms, VisibilityGridLevelPush, VisibilityGridPush};
use crate::scene::Scene;
use crate::settings::params::{AnyParam, Choices, DefaultValue, Param, Range};
use crate::settings::RenderSettings;
use crate::vk::barrier;
use crate::vk::pipeline::{Binding, DescriptorSet, Pipeline, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::{Buffer, Gpu};
use anyhow::{bail, Result};
use ash::vk;
use glam::{Mat4, Vec3};
use gpu_allocator::MemoryLocation;

mod triangle_order;
pub use triangle_order::TriangleOrder;

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
    default: DefaultValue::Fixed(Visibility::None),
    range: Range::ANY,
};

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

pub const PARAMS: &[&dyn AnyParam] = &[&VISIBILITY, &GRID, &SUBCELLS];

/// The coarsest level has 4 x 4 x 4 cells (whole 32-bit words, and coarser
/// levels would be occupied almost always).
const COARSEST_SIDE: u32 = 4;

/// Levels of a grid of side `n`: n, n/2, ..., 4.
pub fn levels(n: u32) -> u32 {
    n.ilog2() - COARSEST_SIDE.ilog2() + 1
}

/// Whether `s` asks for the voxel grid.
pub fn uses_voxels(s: &RenderSettings) -> bool {
    VISIBILITY.get(s) == Visibility::Voxels
}

/// The warning for `--visibility-grid` set where no run uses the grid
/// (`grid_used`: whether one does), which is most likely a forgotten
/// `--visibility voxels`.
pub fn unused_grid_warning(s: &RenderSettings, grid_used: bool) -> Option<String> {
    let set: Vec<String> = [
        (&GRID, "visibility-grid"),
        (&SUBCELLS, "visibility-subcells"),
    ]
    .into_iter()
    .filter(|(p, _)| p.is_set_in(s))
    .map(|(p, name)| format!("--{name} {}", p.get(s)))
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
/// formula, marches the grid or builds it: `VOXEL_VISIBILITY`
/// (`shaders/vpl.glsl`; the march is compiled only into runs with the grid,
/// as a uniform branch around it slowed every gather on lavapipe) and
/// `GRID_SUB` (`shaders/voxel_grid/layout.glsl`; the layout and the march's
/// sub-cell samples). Shaders without a constant ignore its entry.
pub fn specialization(s: &RenderSettings) -> [Spec; 2] {
    [
        Spec::bool("VOXEL_VISIBILITY", uses_voxels(s)),
        Spec::int("GRID_SUB", SUBCELLS.get(s) as i32),
    ]
}

/// Bytes of the grid of `s` (0 without `--visibility voxels`).
pub fn memory(s: &RenderSettings) -> u64 {
    match uses_voxels(s) {
        true => grid_bytes(GRID.get(s), SUBCELLS.get(s)),
        false => 0,
    }
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

/// Checks, before anything is allocated, that the grid of `s` fits the one
/// storage buffer `gpu` binds it as: with 4 sub-cells at 256 it takes 129
/// MiB (without, at 1024, 147 MiB), past the 128 MiB that some devices
/// (lavapipe among them) bind at once.
pub fn check_device(gpu: &Gpu, s: &RenderSettings) -> Result<()> {
    let (bytes, range) = (memory(s), gpu.limits().max_storage_buffer_range as u64);
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

/// The visibility fields of the run uniforms.
pub fn write_uniforms(s: &RenderSettings, u: &mut RunUniforms) {
    let n = GRID.get(s);
    u.visibility = match VISIBILITY.get(s) {
        Visibility::Voxels => gpu_types::VISIBILITY_VOXELS,
        // Exact is applied on the CPU after the frame (`visibility`).
        Visibility::None | Visibility::Exact => gpu_types::VISIBILITY_NONE,
    };
    u.visibility_side = n as i32;
    u.visibility_levels = levels(n) as i32;
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

/// The grid buffer of `s` (16 bytes when nothing reads it: set 0 binds it
/// whatever the method).
pub fn grid_buffer(gpu: &Gpu, s: &RenderSettings) -> Result<Buffer> {
    Buffer::new(
        gpu,
        "visibility grid",
        memory(s).max(16),
        vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::TRANSFER_DST
            | vk::BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::GpuOnly,
    )
}

/// Lavapipe ends all loops of a shader invocation after 65,535 iterations
/// together (gallivm's loop limiter), silently. A march through the grid
/// takes at most `VISIBILITY_MAX_ITERATIONS` (13, `shaders/voxel_grid/march.glsl`)
/// iterations, its evaluation one more of the caller's loop and one to test
/// the march's condition: this many per evaluation.
pub const LOOP_ITERATIONS_PER_EVALUATION: u64 = 15;

/// What a fragment may spend on loops there, with room for its other loops.
pub const LOOP_BUDGET: u64 = 61_440;

/// Workgroup size of the voxelization (`local_size_x` of
/// `shaders/voxel_grid/voxelize.comp`).
const WORKGROUP: u32 = 64;

/// Triangles per dispatch: 64 per workgroup, at most 65,535 workgroups.
const TRIANGLES_PER_DISPATCH: u32 = WORKGROUP * 65_535;

/// Columns of one large triangle that one invocation takes at most: each
/// is at most 4 sub-cells, about 6 loop iterations, so even 64 triangles
/// across the whole grid in one workgroup stay within lavapipe's 65,535
/// (docs/algorithm.md section 5, "Lavapipe's loop limit").
const COLUMNS_PER_INVOCATION: u32 = 128;

/// Rows of workgroups (the dispatch's y) for the large triangles of a grid
/// of `columns` sub-cells a side: enough that the invocations of a
/// workgroup's rows, sharing a triangle across the whole grid, take at most
/// `COLUMNS_PER_INVOCATION` of its columns each.
pub fn rows_per_triangle(columns: u32) -> u32 {
    (columns * columns).div_ceil(WORKGROUP * COLUMNS_PER_INVOCATION)
}

/// Pass `visibility-grid`.
pub struct VisibilityGridPass {
    /// The voxelization of the large triangles and of the others
    /// (`voxel_grid/voxelize.comp` with `LARGE` true and false).
    large: Pipeline,
    small: Pipeline,
    /// The OR-levels (`voxel_grid/levels.comp`).
    levels: Pipeline,
    set: DescriptorSet,
    order: TriangleOrder,
    /// `order.first_indices` on the GPU (the set's binding 2).
    _order: Buffer,
    /// Each draw's mesh.
    meshes: Vec<usize>,
    /// The grid it clears and fills (bound in the frame set).
    buffer: vk::Buffer,
    bytes: u64,
    /// Rows of workgroups that share each large triangle's columns (of
    /// sub-cells).
    rows: u32,
    /// Finest cells per side, and sub-cells per side of one.
    side: u32,
    sub: u32,
}

impl VisibilityGridPass {
    /// For the grid `grid` (bound as set 0 binding 3 of `setup.frame`) of
    /// `scene` (the CPU copy of `setup.scene`).
    pub fn new(setup: &Setup, grid: &Buffer, scene: &Scene) -> Result<Self> {
        let order = TriangleOrder::new(scene);
        let order_buffer = Buffer::with_data(
            setup.gpu,
            "visibility-grid triangle order",
            bytemuck::cast_slice(&order.first_indices),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let gpu_scene = setup.scene;
        let set = DescriptorSet::new(
            setup.gpu,
            "visibility-grid",
            &[
                Binding::storage("Vertices", &gpu_scene.vertices),
                Binding::storage("Indices", &gpu_scene.indices),
                Binding::storage("Order", &order_buffer),
            ],
        )?;
        let voxelization = |large: bool| {
            let constants = [
                specialization(setup.settings)[1],
                Spec::bool("LARGE", large),
            ];
            Pipeline::compute(
                setup.gpu,
                if large {
                    "visibility-grid large triangles"
                } else {
                    "visibility-grid"
                },
                "voxel_grid/voxelize.comp",
                &[setup.frame, &set],
                std::mem::size_of::<VisibilityGridPush>() as u32,
                &constants,
            )
        };
        let (large, small) = (voxelization(true)?, voxelization(false)?);
        let levels = Pipeline::compute(
            setup.gpu,
            "visibility-grid levels",
            "voxel_grid/levels.comp",
            &[setup.frame],
            std::mem::size_of::<VisibilityGridLevelPush>() as u32,
            &specialization(setup.settings)[1..],
        )?;
        let (side, sub) = (GRID.get(setup.settings), SUBCELLS.get(setup.settings));
        Ok(Self {
            large,
            small,
            levels,
            set,
            order,
            _order: order_buffer,
            meshes: scene.instances.iter().map(|i| i.mesh).collect(),
            buffer: grid.buffer,
            bytes: memory(setup.settings),
            rows: rows_per_triangle(side * sub),
            side,
            sub,
        })
    }

    /// Clears the grid, voxelizes every instance, posed by
    /// `instance_transforms` in the grid's cube `cube` (of this frame), into
    /// its finest level and makes the OR-levels.
    pub fn record(
        &self,
        ctx: &FrameContext,
        profiler: &mut Profiler,
        cube: [f32; 4],
        instance_transforms: &[Mat4],
    ) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let rw = vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
        let per = self.sub as f32 / cube[3];
        profiler.pass(gpu, cmd, "visibility-grid", INDIRECT_COMPUTE, || unsafe {
            // The previous frame's gathers (and readback) read it before it
            // is cleared; the clear comes before the atomics.
            barrier::zero_buffer(
                gpu,
                cmd,
                self.buffer,
                self.bytes,
                (barrier::READERS, vk::AccessFlags2::NONE),
                (vk::PipelineStageFlags2::COMPUTE_SHADER, rw),
            );
            // Each draw's triangles, largest first (`TriangleOrder`): the
            // large ones by whole workgroups, which the dispatch's y rows
            // share too, then the rest by one invocation each. Both only
            // OR bits in with atomics: in any order, the same grid.
            let large = |d: usize| {
                let draw = &ctx.scene.draws[d];
                let m = &instance_transforms[draw.push.instance as usize];
                self.order.large(self.meshes[d], m, per)
            };
            for (pipeline, is_large) in [(&self.large, true), (&self.small, false)] {
                pipeline.bind(
                    gpu,
                    cmd,
                    vk::PipelineBindPoint::COMPUTE,
                    &[ctx.frame_set, self.set.set],
                );
                for (d, draw) in ctx.scene.draws.iter().enumerate() {
                    let l = large(d);
                    let (mut first, end) = match is_large {
                        true => (0, l),
                        false => (l, draw.index_count / 3),
                    };
                    let rows = if is_large { self.rows } else { 1 };
                    while first < end {
                        let n = (end - first).min(TRIANGLES_PER_DISPATCH);
                        let push = VisibilityGridPush {
                            first_index: draw.first_index,
                            vertex_offset: draw.vertex_offset,
                            instance: draw.push.instance,
                            first_triangle: first,
                            triangles: n,
                        };
                        gpu.device.cmd_push_constants(
                            cmd,
                            pipeline.layout,
                            vk::ShaderStageFlags::COMPUTE,
                            0,
                            bytemuck::bytes_of(&push),
                        );
                        gpu.device.cmd_dispatch(cmd, n.div_ceil(WORKGROUP), rows, 1);
                        first += n;
                    }
                }
            }
            // Each OR-level reads the level below it whole: the
            // voxelization's atomics, or the previous OR-level, come first.
            self.levels
                .bind(gpu, cmd, vk::PipelineBindPoint::COMPUTE, &[ctx.frame_set]);
            for k in 0..levels(self.side) - 1 {
                barrier::memory(
                    gpu,
                    cmd,
                    vk::PipelineStageFlags2::COMPUTE_SHADER,
                    rw,
                    vk::PipelineStageFlags2::COMPUTE_SHADER,
                    rw,
                );
                let push = VisibilityGridLevelPush { level: k as i32 };
                gpu.device.cmd_push_constants(
                    cmd,
                    self.levels.layout,
                    vk::ShaderStageFlags::COMPUTE,
                    0,
                    bytemuck::bytes_of(&push),
                );
                let words = (self.side >> (k + 1)).pow(3) / 32;
                gpu.device.cmd_dispatch(cmd, words.div_ceil(64), 1, 1);
            }
            // Every later reader: the patch formula in fragment shaders (and
            // any stage), the readback copy.
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
                barrier::READERS,
                vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::TRANSFER_READ,
            );
        });
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
    fn no_invocation_takes_more_than_its_columns_of_a_large_triangle() {
        // The plain grid at 64: one row; 4 sub-cells at 64: 8 rows.
        assert_eq!(rows_per_triangle(64), 1);
        assert_eq!(rows_per_triangle(256), 8);
        assert_eq!(rows_per_triangle(16), 1);
        for columns in [16u32, 32, 64, 128, 256, 512, 1024, 4096] {
            let shared = WORKGROUP * rows_per_triangle(columns);
            assert!(
                (columns * columns).div_ceil(shared) <= COLUMNS_PER_INVOCATION,
                "{columns}"
            );
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
