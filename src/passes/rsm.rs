//! Pass `rsm`: the reflective shadow map (docs/algorithm.md section 2),
//! rendered from the spot light with `shaders/scene.vert` + `shaders/rsm.frag`.
//! Reads the scene; writes `rsm_position` (xyz, area), `rsm_normal` (xyz,
//! patch state), `rsm_flux` (rgb, solid angle) and `rsm_depth` (barriers:
//! `ScenePass::record`).

use super::ScenePass;
use crate::frame::Setup;
use anyhow::Result;

pub fn new(setup: &Setup) -> Result<ScenePass> {
    ScenePass::new(setup, "rsm", "rsm.frag", true, |t| {
        ([&t.rsm_position, &t.rsm_normal, &t.rsm_flux], &t.rsm_depth)
    })
}
