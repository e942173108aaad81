//! Pass `voxel-grid`: clears the grid, voxelizes every instance's
//! triangles, posed by this frame's transforms, into the finest level of the
//! cube [`grid_cube`](super::grid_cube) puts around them (the large
//! triangles by whole workgroups, the rest one per invocation:
//! [`TriangleOrder`]), then makes each coarser level the OR of the one below
//! it (`shaders/voxel_grid/voxelize.comp`, `shaders/voxel_grid/levels.comp`).
//!
//! Barriers (in `record`): the previous frame's readers (shaders of every
//! stage, the readback copy) before the clear; the clear before the
//! voxelization's atomics (none between its dispatches: they only OR bits
//! in); the atomics before the first OR-level, each OR-level before the
//! next; the last before every later reader.

use super::{bytes, levels, specialization, TriangleOrder, VoxelGrid, GRID, SUBCELLS};
use crate::frame::{FrameContext, Setup};
use crate::gpu_types::{GridLevelPush, VoxelizePush};
use crate::passes::INDIRECT_COMPUTE;
use crate::scene::Scene;
use crate::vk::barrier;
use crate::vk::pipeline::{Binding, DescriptorSet, Pipeline, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::Result;
use ash::vk;
use glam::Mat4;

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

/// Pass `voxel-grid`.
pub struct VoxelizePass {
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

impl VoxelizePass {
    /// For the grid `grid` (bound in `setup.frame`) of `scene` (the CPU copy
    /// of `setup.scene`).
    pub fn new(setup: &Setup, grid: &VoxelGrid, scene: &Scene) -> Result<Self> {
        let order = TriangleOrder::new(scene);
        let order_buffer = Buffer::with_data(
            setup.gpu,
            "voxel-grid triangle order",
            bytemuck::cast_slice(&order.first_indices),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let gpu_scene = setup.scene;
        let set = DescriptorSet::new(
            setup.gpu,
            "voxel-grid",
            &[
                Binding::storage("Vertices", &gpu_scene.vertices),
                Binding::storage("Indices", &gpu_scene.indices),
                Binding::storage("Order", &order_buffer),
            ],
        )?;
        let voxelization = |large: bool| {
            let constants = [specialization(setup.settings), Spec::bool("LARGE", large)];
            Pipeline::compute(
                setup.gpu,
                if large {
                    "voxel-grid large triangles"
                } else {
                    "voxel-grid"
                },
                "voxel_grid/voxelize.comp",
                &[setup.frame, &set],
                std::mem::size_of::<VoxelizePush>() as u32,
                &constants,
            )
        };
        let (large, small) = (voxelization(true)?, voxelization(false)?);
        let levels = Pipeline::compute(
            setup.gpu,
            "voxel-grid levels",
            "voxel_grid/levels.comp",
            &[setup.frame],
            std::mem::size_of::<GridLevelPush>() as u32,
            &[specialization(setup.settings)],
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
            buffer: grid.occupancy.buffer,
            bytes: bytes(setup.settings),
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
        profiler.pass(gpu, cmd, "voxel-grid", INDIRECT_COMPUTE, || unsafe {
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
                        let push = VoxelizePush {
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
                let push = GridLevelPush { level: k as i32 };
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
}
