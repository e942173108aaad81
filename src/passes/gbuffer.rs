//! Pass `gbuffer`: depth, world position, normal and albedo from the camera
//! (docs/algorithm.md section 3, step 1), with `shaders/scene.vert` +
//! `shaders/gbuffer.frag`. Reads the scene; writes `gbuffer_position`,
//! `gbuffer_normal`, `gbuffer_albedo`, `gbuffer_depth` (barriers: `ScenePass::record`).

use super::ScenePass;
use crate::frame::Setup;
use anyhow::Result;

pub fn new(setup: &Setup) -> Result<ScenePass> {
    ScenePass::new(setup, "gbuffer", "gbuffer.frag", false, |t| {
        (
            [&t.gbuffer_position, &t.gbuffer_normal, &t.gbuffer_albedo],
            &t.gbuffer_depth,
        )
    })
}
