//! Indirect visibility (issue 25; docs/algorithm.md sections 1 and 5,
//! "Exact indirect visibility"):
//! whether a VPL can see the receiver it lights, which the VPL methods
//! here do not model.
//!
//! `--visibility exact` (`visibility::VISIBILITY`) is the limit,
//! for the dense `reference`: its gather
//! (every RSM texel a VPL, `shaders/rsm_gather/gather.frag`'s `patch_irradiance`)
//! run on the CPU with one ray per (receiver, VPL) through the path tracer's
//! BVH (`pathtrace::Occluders`). Against the path-traced truth it is the
//! VPL model's own error (texel-sized VPLs, the disc term `A_j`); the
//! reference without it against it, the error of ignoring visibility. It
//! costs pixels x lit texels rays: seconds at 64x64 with RSM 64, minutes
//! at 256x256 with RSM 256 (a progress bar shows them).

use crate::pathtrace::Occluders;
use crate::readback::{Readback, RsmReadback};
use crate::renderer::Renderer;
use crate::scene::Scene;
use anyhow::Result;
use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A virtual point light: an RSM texel's surface point (world space), its
/// normal, reflected flux and area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vpl {
    pub position: Vec3,
    pub normal: Vec3,
    pub flux: Vec3,
    pub area: f32,
}

/// Every lit texel of one RSM as a VPL (what `reference` gathers).
pub fn texel_vpls(rsm: &RsmReadback) -> Vec<Vpl> {
    (0..rsm.position.len())
        .filter(|&k| rsm.position[k][3] > 0.0)
        .map(|k| {
            let (p, n, f) = (rsm.position[k], rsm.normal[k], rsm.flux[k]);
            Vpl {
                position: Vec3::new(p[0], p[1], p[2]),
                normal: Vec3::new(n[0], n[1], n[2]),
                flux: Vec3::new(f[0], f[1], f[2]),
                area: p[3],
            }
        })
        .filter(|v| v.flux.max_element() > 0.0)
        .collect()
}

/// Irradiance at receiver `x` (normal `n`) from `v`: docs/algorithm.md
/// section 2.6, `Phi cos_i cos_j / (pi d^2 + A)`, as `shaders/vpl.glsl`.
pub fn patch_irradiance(x: Vec3, n: Vec3, v: &Vpl) -> Vec3 {
    let d = v.position - x;
    let d2 = d.length_squared();
    let dir = d / d2.max(1e-30).sqrt();
    let cos_i = n.dot(dir).max(0.0);
    let cos_j = (-v.normal.dot(dir)).max(0.0);
    v.flux * (cos_i * cos_j / (PI * d2 + v.area))
}

/// The indirect irradiance (W/m^2) of every pixel of the G-buffer `g` from
/// `vpls`, each VPL counted only where `occluders` (if any) let it see the
/// receiver. `progress(rows_done, rows)` from a helper thread.
pub fn gather(
    g: &Readback,
    vpls: &[Vpl],
    occluders: Option<&Occluders>,
    progress: impl Fn(usize, usize) + Sync,
) -> Vec<[f32; 4]> {
    let (w, h) = (g.width as usize, g.height as usize);
    let mut out = vec![[0.0f32; 4]; w * h];
    let done = AtomicUsize::new(0);
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, e) in row.iter_mut().enumerate() {
            let k = y * w + x;
            let p = g.position[k];
            if p[3] <= 0.0 {
                continue;
            }
            let at = Vec3::new(p[0], p[1], p[2]);
            let n = Vec3::from_slice(&g.normal[k][..3]).normalize_or_zero();
            let mut sum = Vec3::ZERO;
            for v in vpls {
                let c = patch_irradiance(at, n, v);
                if c.max_element() > 0.0 && occluders.is_none_or(|o| o.visible(at, n, v.position)) {
                    sum += c;
                }
            }
            *e = sum.extend(0.0).to_array();
        }
        progress(done.fetch_add(1, Ordering::Relaxed) + 1, h);
    });
    out
}

/// Every VPL of the frame `r` last rendered, whose readback is `out`: the
/// RSM texels of each of its light views (one view's are in `out`; with
/// several, each is rendered alone to read its RSM, and all again after).
pub fn frame_vpls(r: &mut Renderer, out: &Readback) -> Result<Vec<Vpl>> {
    let views = r.light_views().len();
    if views == 1 {
        return Ok(texel_vpls(&out.rsm));
    }
    let mut vpls = vec![];
    for v in 0..views {
        r.set_only_view(Some(v))?;
        r.render_frames(1, |_| {})?;
        vpls.extend(texel_vpls(&r.readback()?.rsm));
    }
    r.set_only_view(None)?;
    Ok(vpls)
}

/// `out` (a frame of `reference` rendered by `r` from `posed`, the scene as
/// posed for it) with its indirect light gathered again with exact
/// visibility, and its final image composed again from it.
pub fn with_exact_visibility(
    r: &mut Renderer,
    posed: &Scene,
    mut out: Readback,
    exposure: f32,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<Readback> {
    let vpls = frame_vpls(r, &out)?;
    let occluders = Occluders::new(posed);
    out.indirect = gather(&out, &vpls, Some(&occluders), progress);
    compose(&mut out, exposure);
    Ok(out)
}

/// The final image and its display from the direct and indirect layers:
/// `direct + albedo / pi * E` (section 2.6), as `shaders/composite.frag`.
fn compose(out: &mut Readback, exposure: f32) {
    for k in 0..out.final_radiance.len() {
        let (d, e, rho) = (out.direct[k], out.indirect[k], out.albedo[k]);
        for c in 0..3 {
            out.final_radiance[k][c] = d[c] + rho[c] / PI * e[c];
        }
    }
    out.display = out
        .final_radiance
        .iter()
        .flat_map(|c| {
            let s = |v: f32| crate::debug_view::srgb(v * exposure);
            [s(c[0]), s(c[1]), s(c[2]), 255]
        })
        .collect();
}
