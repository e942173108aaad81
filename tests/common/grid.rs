//! Indirect visibility's voxel grid in the tests: the settings that turn it
//! on or change it, and the grid read back after a frame.

use super::assert_validation_clean;
use glam::DVec3;
use isr::renderer::Renderer;
use isr::scene::Scene;
use isr::settings::RenderSettings;
use isr::vk::Gpu;

/// The voxel grid after one frame of `scene` with `settings` (which use it):
/// its words as read back (`shaders/voxel_grid/layout.glsl`), its cube
/// (`Renderer::grid_cube`, relative to the render origin) and the
/// render origin. Fails the test if validation spoke.
pub fn rendered_grid(
    gpu: &Gpu,
    scene: &Scene,
    settings: &RenderSettings,
) -> (Vec<u32>, [f32; 4], DVec3) {
    let mut r = Renderer::new(gpu, scene, settings).expect("renderer setup");
    r.render_frames(1, |_| {}).expect("rendering");
    let grid = r.voxel_grid().expect("a run with the voxel grid");
    let words =
        bytemuck::cast_slice(&isr::readback::read_buffer(gpu, grid).expect("readback")).to_vec();
    let (cube, origin) = (r.grid_cube(), r.render_origin());
    drop(r);
    assert_validation_clean(gpu);
    (words, cube, origin)
}

/// `s` with `--visibility voxels` at grid side `n`.
pub fn voxels(mut s: RenderSettings, n: u32) -> RenderSettings {
    use isr::visibility::{Visibility, VISIBILITY};
    use isr::voxel_grid::GRID;
    VISIBILITY.set(&mut s, Visibility::Voxels);
    GRID.set(&mut s, n);
    s
}

/// `s` with the plain grid: one bit per finest cell, no sub-cells
/// (`--visibility-subcells 1`).
pub fn plain_grid(mut s: RenderSettings) -> RenderSettings {
    isr::voxel_grid::SUBCELLS.set(&mut s, 1);
    s
}

/// `s` with HISR marching from every receiver (`--hisr-shared-visibility
/// off`; the default shares the tiles' visibility).
pub fn per_receiver(mut s: RenderSettings) -> RenderSettings {
    isr::methods::hisr::SHARED_VISIBILITY.set(&mut s, false);
    s
}
