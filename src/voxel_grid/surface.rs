//! The surface inside each finest cell of the voxel grid (docs/algorithm.md
//! section 5.8): its area, albedo, normal and centroid, summed by pass
//! `voxel-surface` ([`SurfacePass`]) from this frame's posed scene, for the
//! passes that treat cells as pieces of surface (light leaving a cell is its
//! albedo times the irradiance it receives times its area, section 11 of
//! the shared algorithm notes). The layout is `shaders/voxel_grid/
//! surface.glsl`'s, mirrored here ([`SURFACE_WORDS`], [`SURFACE_ONE`]).
//!
//! The pass rasterizes every instance three times, once along each axis of
//! the grid, `GRID_SAMPLES` fragments per cell side, and each triangle keeps
//! only the fragments of its dominant axis: every fragment is the piece of
//! one triangle over one sample, which adds its area, albedo times area,
//! normal times area and place times area to its cell with integer atomics
//! (the same sums whatever order fragments come in). A triangle covers each
//! sample centre with the probability of its projected area, so areas are
//! counted without bias at any triangle size.
//!
//! Barriers (in `record`): the previous frame's readers before the clear;
//! the clear before the fragment atomics; the atomics before every later
//! reader.

use super::{GRID, SUBCELLS};
use crate::frame::{FrameContext, Setup};
use crate::gpu_types::DrawPush;
use crate::passes::{begin_rendering, draw_scene_with, Attachments, INDIRECT_GRAPHICS};
use crate::settings::RenderSettings;
use crate::vk::barrier;
use crate::vk::pipeline::{Binding, DescriptorSet, GraphicsDesc, Pipeline, Spec};
use crate::vk::profiler::Profiler;
use crate::vk::Buffer;
use anyhow::Result;
use ash::vk;
use glam::Vec3;

/// Words per finest cell, as in `shaders/voxel_grid/surface.glsl`.
pub const SURFACE_WORDS: usize = 12;

/// The fixed point of the sums: a cell face's area is this many units, as
/// in `shaders/voxel_grid/surface.glsl`.
pub const SURFACE_ONE: f32 = 65536.0;

/// Fragments per cell side (`GRID_SAMPLES`): the samples of a cell's face
/// that a triangle's area is counted at. With 4 sub-cells per cell the grid
/// resolves occupancy at the same spacing.
pub fn samples(s: &RenderSettings) -> u32 {
    SUBCELLS.get(s).max(4)
}

/// Bytes of the surface sums of the grid of `s`.
pub fn bytes(s: &RenderSettings) -> u64 {
    (GRID.get(s) as u64).pow(3) * SURFACE_WORDS as u64 * 4
}

/// The surface inside one finest cell, decoded.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceCell {
    /// In units of a cell face's area.
    pub area: f32,
    /// The area-weighted mean albedo (linear RGB).
    pub albedo: Vec3,
    /// The area-weighted sum of unit normals over the area: its length is 1
    /// on a flat piece and falls where the surface bends or folds.
    pub normal: Vec3,
    /// The area-weighted mean place inside the cell (0 to 1 per axis).
    pub centroid: Vec3,
}

/// The cells of a readback of the surface sums (`Renderer::voxel_surface`),
/// in the grid's order (x fastest).
pub fn decode(words: &[u32]) -> Vec<SurfaceCell> {
    words
        .chunks_exact(SURFACE_WORDS)
        .map(|w| {
            let area = w[0] as f32 / SURFACE_ONE;
            let per = |k: usize, signed: bool| {
                let v = |i: usize| match signed {
                    true => w[k + i] as i32 as f32,
                    false => w[k + i] as f32,
                };
                Vec3::new(v(0), v(1), v(2)) / SURFACE_ONE
            };
            let mean = |v: Vec3| if area > 0.0 { v / area } else { Vec3::ZERO };
            SurfaceCell {
                area,
                albedo: mean(per(1, false)),
                normal: mean(per(4, true)),
                centroid: mean(per(7, false)),
            }
        })
        .collect()
}

/// Pass `voxel-surface`.
pub struct SurfacePass {
    pipeline: Pipeline,
    set: DescriptorSet,
    buffer: vk::Buffer,
    bytes: u64,
    /// The image's side: cells per side times samples per cell side.
    side: u32,
}

impl SurfacePass {
    /// Fills `surface` (the grid's surface sums) from the scene of `setup`.
    pub fn new(setup: &Setup, surface: &Buffer) -> Result<Self> {
        let set = DescriptorSet::new(
            setup.gpu,
            "voxel-surface",
            &[Binding::storage("GridSurface", surface)],
        )?;
        let samples = samples(setup.settings);
        let pipeline = Pipeline::graphics(
            setup.gpu,
            &GraphicsDesc {
                name: "voxel-surface",
                vertex_shader: "voxel_grid/surface.vert",
                fragment_shader: "voxel_grid/surface.frag",
                sets: &[setup.frame, &setup.scene.set, &set],
                push_constant_bytes: std::mem::size_of::<DrawPush>() as u32,
                scene_vertices: true,
                specialization: &[
                    Spec::int("TEXTURE_ARRAYS", setup.scene.texture_arrays_in_use()),
                    Spec::int("GRID_SAMPLES", samples as i32),
                ],
                // Both faces count: cull modes are set per draw, as dynamic state.
                dynamic_cull: true,
                ..Default::default()
            },
        )?;
        Ok(Self {
            pipeline,
            set,
            buffer: surface.buffer,
            bytes: bytes(setup.settings),
            side: GRID.get(setup.settings) * samples,
        })
    }

    pub fn record(&self, ctx: &FrameContext, profiler: &mut Profiler) {
        let (gpu, cmd) = (ctx.gpu, ctx.cmd);
        let rw = vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE;
        profiler.pass(gpu, cmd, "voxel-surface", INDIRECT_GRAPHICS, || {
            // The previous frame's readers before the clear; the clear
            // before the fragments' atomics.
            barrier::zero_buffer(
                gpu,
                cmd,
                self.buffer,
                self.bytes,
                (barrier::READERS, vk::AccessFlags2::NONE),
                (vk::PipelineStageFlags2::FRAGMENT_SHADER, rw),
            );
            let extent = vk::Extent2D {
                width: self.side,
                height: self.side,
            };
            begin_rendering(gpu, cmd, &Attachments::simple(&[], None, extent));
            // Three instances: the axes (surface.vert), both faces drawn.
            draw_scene_with(ctx, &self.pipeline, ctx.scene, 3, &[self.set.set], false);
            unsafe { gpu.device.cmd_end_rendering(cmd) };
            barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::FRAGMENT_SHADER,
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
    fn cells_decode_their_means() {
        let one = SURFACE_ONE as u32;
        let mut w = vec![0u32; 2 * SURFACE_WORDS];
        // Two cell faces of area, albedo 0.5, normal -y, centroid (0.25, 0.5, 1).
        w[0] = 2 * one;
        w[1..4].copy_from_slice(&[one, one, one]);
        w[4..7].copy_from_slice(&[0, (-2 * one as i32) as u32, 0]);
        w[7..10].copy_from_slice(&[one / 2, one, 2 * one]);
        let c = decode(&w);
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].area, 2.0);
        assert_eq!(c[0].albedo, Vec3::splat(0.5));
        assert_eq!(c[0].normal, Vec3::new(0.0, -1.0, 0.0));
        assert_eq!(c[0].centroid, Vec3::new(0.25, 0.5, 1.0));
        assert_eq!(c[1], SurfaceCell::default());
    }
}
