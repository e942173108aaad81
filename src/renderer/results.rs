//! Reading a run's results back to the host (`Renderer::readback` and the
//! method's own buffers), positions moved from render-origin space back to
//! world space.

use super::Renderer;
use crate::gpu_types::LightPatch;
use crate::multires::MultiresBuffer;
use crate::readback::{self, MultiresReadback, Readback};
use anyhow::Result;

impl Renderer<'_> {
    /// Copies every output of the last frame back to the host, positions
    /// in world space.
    pub fn readback(&self) -> Result<Readback> {
        let mut r = readback::read_frame(self.gpu, &self.targets)?;
        readback::to_world(&mut r.position, self.origin);
        readback::to_world(&mut r.rsm.position, self.origin);
        Ok(r)
    }

    /// What the GPU renders relative to (`scene::render_origin`).
    pub fn render_origin(&self) -> glam::DVec3 {
        self.origin
    }

    /// The multiresolution buffer of the last frame, if the method has one,
    /// positions in world space.
    pub fn readback_multires(&self) -> Result<Option<MultiresReadback>> {
        let Some(m) = self.method.multires() else {
            return Ok(None);
        };
        let mut r = readback::read_multires(self.gpu, m, &self.targets)?;
        for level in &mut r.geo_mean {
            readback::to_world(level, self.origin);
        }
        for level in &mut r.rsm_tree {
            readback::to_world(&mut level[0], self.origin);
        }
        Ok(Some(r))
    }

    /// The multiresolution buffer, if the method has one.
    pub fn multires(&self) -> Option<&MultiresBuffer> {
        self.method.multires()
    }

    /// The light patches the method's light-space source offered the
    /// gather in the last frame (`None` for a method without one): a list,
    /// or a packed tree root first (`shaders/hisr/tree_pack.comp`),
    /// positions in world space.
    pub fn light_patches(&self) -> Result<Option<Vec<LightPatch>>> {
        let Some(l) = self.method.light_patches() else {
            return Ok(None);
        };
        let mut patches = readback::read_light_patches(self.gpu, l.buffer)?;
        let mut positions: Vec<[f32; 4]> = patches.iter().map(|p| p.position_area).collect();
        readback::to_world(&mut positions, self.origin);
        for (p, q) in patches.iter_mut().zip(positions) {
            p.position_area = q;
        }
        Ok(Some(patches))
    }

    /// How many light patches the method's source chose in the last frame,
    /// for a source that chooses them anew every frame.
    pub fn light_patches_chosen(&self) -> Result<Option<u32>> {
        match self.method.light_patches() {
            Some(l) if l.chosen_per_frame => Ok(self.light_patches()?.map(|c| c.len() as u32)),
            _ => Ok(None),
        }
    }
}
