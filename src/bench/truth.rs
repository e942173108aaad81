//! Comparing with the path-traced truth (docs/algorithm.md section 6.6): the
//! pixels where a rasterizer and a path tracer can be compared at all.
//!
//! Two kinds of pixel differ by construction, whatever the radiometry:
//! - geometric edges: the rasterizer samples the pixel's centre, the path
//!   tracer averages over the pixel, so where normals or depths jump their
//!   coverage differs;
//! - direct-light shadow edges: percentage-closer filtering blurs a shadow
//!   over its filter's footprint in the shadow map, the path tracer's
//!   shadows are exact. The footprint is measured in shadow-map texels
//!   (`RenderSettings::shadow_size`, in each view's shadow frustum), so the
//!   band is found in the light's view, not the camera's: at a grazing
//!   light one texel can span many pixels.

use crate::bounces::Bounces;
use crate::readback::Readback;
use crate::scene::LightKind;
use crate::view::LightView;
use glam::{DVec3, Vec2, Vec3};

/// A kink: the normal's second difference across three pixels in a row
/// (L1) over this. A second difference, so that a smoothly shaded curved
/// surface (whose normal turns steadily, and whose pixel mean the centre
/// sample matches to first order) is not an edge, and a facet's is.
const NORMAL_KINK: f32 = 0.1;
/// A step: the view depth's second difference over this fraction of the
/// depth (a plane's, even seen at a grazing angle, is a small fraction).
const DEPTH_STEP: f32 = 0.05;
/// Neighbours whose exact direct light differs by more than this fraction
/// of the larger have a shadow edge between them.
const SHADOW_JUMP: f32 = 0.25;
/// How far (pixels) from a shadow edge a pixel can be and still lie in its
/// PCF band; a wider band (a light grazing the surface) is cut here.
const MAX_BAND_PIXELS: i32 = 24;

/// The shadow maps a frame was rendered with: where each pixel falls in
/// them and how wide PCF's footprint is there.
pub struct ShadowMaps<'a> {
    pub views: &'a [LightView],
    /// The render origin the views' matrices are relative to.
    pub origin: DVec3,
    /// The shadow map's side S (`RenderSettings::shadow_size`).
    pub resolution: u32,
    /// Half-width of the band PCF may blur (shadow-map texels): its taps' spacing
    /// plus the hardware 2x2 compare's texel, plus half a texel for where
    /// the shadow map rasterised the occluder's edge.
    pub band_texels: f32,
}

impl<'a> ShadowMaps<'a> {
    /// `resolution`: the shadow map's side (`RenderSettings::shadow_size`);
    /// `pcf_radius`: the PCF tap spacing in texels (`RenderSettings`).
    pub fn new(views: &'a [LightView], origin: DVec3, resolution: u32, pcf_radius: f32) -> Self {
        ShadowMaps {
            views,
            origin,
            resolution,
            band_texels: pcf_radius + 1.5,
        }
    }

    /// Texel coordinates of world point `p` in view `v`'s shadow map, if
    /// in front of it.
    fn texel(&self, v: &LightView, p: Vec3) -> Option<Vec2> {
        let rel = (p.as_dvec3() - self.origin).as_vec3();
        let clip = v.shadow.view_proj * rel.extend(1.0);
        (clip.w > 0.0).then(|| {
            let ndc = Vec2::new(clip.x, clip.y) / clip.w;
            (ndc + 1.0) * 0.5 * self.resolution as f32
        })
    }

    /// The views `p` is seen in: every spot or directional view, and the
    /// one cube face of each point light that holds it.
    fn views_of(&self, p: Vec3) -> Vec<usize> {
        let r = self.resolution as f32;
        let mut chosen = Vec::new();
        for (i, v) in self.views.iter().enumerate() {
            let inside = self
                .texel(v, p)
                .is_some_and(|t| t.x >= 0.0 && t.y >= 0.0 && t.x <= r && t.y <= r);
            let taken = v.kind == LightKind::Point
                && chosen
                    .iter()
                    .any(|&j: &usize| self.views[j].light == v.light);
            if inside && !taken {
                chosen.push(i);
            }
        }
        chosen
    }
}

/// Which pixels of a frame are compared with the path tracer, and how many.
pub struct TruthMask {
    pub mask: Vec<bool>,
    /// Pixels with geometry.
    pub geometry: usize,
    /// Of those, left out at geometric edges, and at shadow edges only.
    pub geometric_edges: usize,
    pub shadow_edges: usize,
}

impl TruthMask {
    pub fn kept(&self) -> usize {
        self.mask.iter().filter(|m| **m).count()
    }

    /// The fraction of pixels with geometry left out (0 with none).
    pub fn left_out(&self) -> f64 {
        if self.geometry == 0 {
            0.0
        } else {
            1.0 - self.kept() as f64 / self.geometry as f64
        }
    }
}

/// The pixels with geometry that lie away from geometric edges (a normal or
/// depth discontinuity in the G-buffer `g`, grown by one pixel) and from
/// shadow edges of the exact direct light `traced_direct` (a jump between
/// neighbours on one surface), grown by PCF's band in `shadows`.
pub fn truth_mask(g: &Readback, traced_direct: &[[f32; 4]], shadows: &ShadowMaps) -> TruthMask {
    let (w, h) = (g.width as i32, g.height as i32);
    let index = |x: i32, y: i32| (y * w + x) as usize;
    let inside = |x: i32, y: i32| x >= 0 && y >= 0 && x < w && y < h;
    let n = (w * h) as usize;
    let geometry: Vec<bool> = (0..n).map(|k| g.position[k][3] > 0.0).collect();
    let normal = |k: usize| Vec3::from_slice(&g.normal[k][..3]);
    let depth = |k: usize| g.position[k][3];
    // Whether the surface bends or breaks between a, b and c (in a row):
    // background on either side, a kink in the normal or a step in depth.
    let breaks = |a: usize, b: usize, c: usize| {
        if !(geometry[a] && geometry[b] && geometry[c]) {
            return true;
        }
        let kink = (normal(a) - 2.0 * normal(b) + normal(c))
            .abs()
            .element_sum();
        let step = (depth(a) - 2.0 * depth(b) + depth(c)).abs();
        kink > NORMAL_KINK || step > DEPTH_STEP * depth(b)
    };
    // A pixel at an edge: its surface breaks across it in x or y. A step
    // between two pixels shows in both their second differences; a pixel
    // on the image's border has none across it.
    let mut edge = vec![false; n];
    for y in 0..h {
        for x in 0..w {
            let k = index(x, y);
            edge[k] = geometry[k]
                && [(1, 0), (0, 1)].iter().any(|&(dx, dy)| {
                    inside(x - dx, y - dy)
                        && inside(x + dx, y + dy)
                        && breaks(index(x - dx, y - dy), k, index(x + dx, y + dy))
                });
        }
    }
    let light = |k: usize| traced_direct[k][0] + traced_direct[k][1] + traced_direct[k][2];
    let mean = {
        let lit: Vec<f32> = (0..n).filter(|&k| geometry[k]).map(light).collect();
        lit.iter().map(|&v| v as f64).sum::<f64>() / lit.len().max(1) as f64
    };

    let mut away_from_geometric_edges = vec![false; n];
    let mut shadow_edge = vec![false; n];
    for y in 0..h {
        for x in 0..w {
            let k = index(x, y);
            if !geometry[k] {
                continue;
            }
            // Grown by one pixel.
            away_from_geometric_edges[k] = (-1..=1).all(|dy| {
                (-1..=1).all(|dx| {
                    let (qx, qy) = (x + dx, y + dy);
                    !inside(qx, qy) || !edge[index(qx, qy)]
                })
            });
            // A jump in exact direct light between neighbours on one
            // smooth surface.
            shadow_edge[k] = !edge[k]
                && [(1, 0), (-1, 0), (0, 1), (0, -1)].iter().any(|&(dx, dy)| {
                    let (qx, qy) = (x + dx, y + dy);
                    if !inside(qx, qy) || edge[index(qx, qy)] || !geometry[index(qx, qy)] {
                        return false;
                    }
                    let (a, b) = (light(k), light(index(qx, qy)));
                    let jump = (a - b).abs();
                    jump > SHADOW_JUMP * a.max(b) && jump as f64 > 1e-3 * mean
                });
        }
    }

    let positions: Vec<Vec3> = g
        .position
        .iter()
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    let band2 = shadows.band_texels * shadows.band_texels;
    let mut mask = vec![false; n];
    let (mut geometric_edges, mut shadow_edges) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let k = index(x, y);
            if !geometry[k] {
                continue;
            }
            if !away_from_geometric_edges[k] {
                geometric_edges += 1;
                continue;
            }
            let views = shadows.views_of(positions[k]);
            let near_shadow_edge = views.iter().any(|&v| {
                let view = &shadows.views[v];
                let Some(tp) = shadows.texel(view, positions[k]) else {
                    return false;
                };
                (-MAX_BAND_PIXELS..=MAX_BAND_PIXELS).any(|dy| {
                    (-MAX_BAND_PIXELS..=MAX_BAND_PIXELS).any(|dx| {
                        let (qx, qy) = (x + dx, y + dy);
                        if !inside(qx, qy) || !shadow_edge[index(qx, qy)] {
                            return false;
                        }
                        shadows
                            .texel(view, positions[index(qx, qy)])
                            .is_some_and(|tq| tq.distance_squared(tp) <= band2)
                    })
                })
            });
            if near_shadow_edge {
                shadow_edges += 1;
            } else {
                mask[k] = true;
            }
        }
    }
    TruthMask {
        mask,
        geometry: geometry.iter().filter(|g| **g).count(),
        geometric_edges,
        shadow_edges,
    }
}

/// The path tracer's noise the bench aims under: the relative RMSE of its
/// indirect image's Monte Carlo noise over the compared pixels (issue 26).
pub const NOISE_TARGET: f64 = 0.02;
/// Samples per pixel of each half's first pass, and the most in all.
const FIRST_SPP: u32 = 16;
pub const MAX_SPP: u32 = 16384;

/// One frame's path-traced truth: its image (the sum of both halves, its
/// layers by bounce included), the pixels it is compared on, its bounces,
/// samples per pixel and measured noise (of its whole indirect image; and
/// of the sum of its first n layers, `noises[n - 1]`).
pub struct Truth {
    pub image: Readback,
    pub bounces: Bounces,
    pub mask: TruthMask,
    pub spp: u32,
    pub noise: f64,
    pub noises: Vec<f64>,
}

/// The sum of the first `n` layers by bounce of `r` (its indirect image
/// where `n` is all of them): the image of `n` bounces.
pub fn first_layers(r: &Readback, n: usize) -> Vec<[f32; 4]> {
    if n >= r.bounces.len() {
        return r.indirect.clone();
    }
    let mut out = vec![[0.0, 0.0, 0.0, 1.0]; r.indirect.len()];
    for layer in &r.bounces[..n] {
        for (o, v) in out.iter_mut().zip(layer) {
            for c in 0..3 {
                o[c] += v[c];
            }
        }
    }
    out
}

impl Truth {
    /// The relative RMSE of indirect radiance `x` against this truth over
    /// its mask, with the truth's own noise taken out in quadrature
    /// (independent errors add so): the error of the model, not of the
    /// truth's sampling.
    pub fn model_error(&self, x: &[[f32; 4]]) -> f64 {
        let e = super::metrics::relative_rmse(x, &self.image.indirect, &self.mask.mask);
        (e * e - self.noise * self.noise).max(0.0).sqrt()
    }

    /// The truth of `b` bounces this truth holds, with its noise: itself,
    /// or for a count under 4 and under its own, the sum of its first
    /// layers (docs/algorithm.md section 6.6); `None` for more than it has,
    /// or a count its fourth layer (bounces 4 and on, together) mixes.
    pub fn of(&self, b: Bounces) -> Option<(Vec<[f32; 4]>, f64)> {
        if b == self.bounces {
            return Some((self.image.indirect.clone(), self.noise));
        }
        let n = b.last()? as usize;
        let holds = self.bounces.last().is_none_or(|m| n as u32 <= m);
        (holds && n < crate::bounces::LAYERS.len() && n <= self.image.bounces.len())
            .then(|| (first_layers(&self.image, n), self.noises[n - 1]))
    }
}

/// Two independent estimates of the indirect image (odd and even seeds),
/// each a sample-weighted mean (and so their layers by bounce); their
/// difference measures the noise of their mean without knowing the answer.
struct Halves {
    a: Readback,
    b: Readback,
    spp: u32,
}

impl Halves {
    fn add(&mut self, a: Readback, b: Readback, spp: u32) {
        let (old, new) = (self.spp as f32, spp as f32);
        let mix = |x: &mut Vec<[f32; 4]>, y: &[[f32; 4]]| {
            for (p, q) in x.iter_mut().zip(y) {
                for c in 0..3 {
                    p[c] = (p[c] * old + q[c] * new) / (old + new);
                }
            }
        };
        mix(&mut self.a.indirect, &a.indirect);
        mix(&mut self.b.indirect, &b.indirect);
        for (x, y) in self.a.bounces.iter_mut().zip(&a.bounces) {
            mix(x, y);
        }
        for (x, y) in self.b.bounces.iter_mut().zip(&b.bounces) {
            mix(x, y);
        }
        self.spp += spp;
    }

    /// The relative RMSE noise of the mean of both halves over `mask`
    /// (of the sum of their first `layers` layers by bounce): each half's
    /// per-pixel variance is `s^2 / n`, their difference's `2 s^2 / n` and
    /// the mean's `s^2 / 2n`, a quarter of the difference's.
    fn noise(&self, mask: &[bool], layers: usize) -> f64 {
        let (a, b) = (first_layers(&self.a, layers), first_layers(&self.b, layers));
        let (mut d, mut m) = (0.0f64, 0.0f64);
        for k in (0..mask.len()).filter(|&k| mask[k]) {
            for c in 0..3 {
                let (x, y) = (a[k][c] as f64, b[k][c] as f64);
                d += (x - y) * (x - y);
                m += 0.25 * (x + y) * (x + y);
            }
        }
        if m == 0.0 {
            0.0
        } else {
            0.5 * (d / m).sqrt()
        }
    }

    /// Both halves averaged: the image the bench compares with.
    fn mean(mut self) -> Readback {
        let average = |x: &mut Vec<[f32; 4]>, y: &[[f32; 4]]| {
            for (p, q) in x.iter_mut().zip(y) {
                for c in 0..3 {
                    p[c] = 0.5 * (p[c] + q[c]);
                }
            }
        };
        average(&mut self.a.indirect, &self.b.indirect);
        for (x, y) in self.a.bounces.iter_mut().zip(&self.b.bounces) {
            average(x, y);
        }
        for (k, f) in self.a.final_radiance.iter_mut().enumerate() {
            let (d, e, rho) = (self.a.direct[k], self.a.indirect[k], self.a.albedo[k]);
            for c in 0..3 {
                f[c] = d[c] + rho[c] / std::f32::consts::PI * e[c];
            }
        }
        self.a
    }
}

/// Path-traces `scene` (posed for the frame) at `g`'s size with `bounces`,
/// doubling up the samples until the noise of its indirect image (every
/// bounce of it together) over the compared pixels (`truth_mask` of the
/// rasterised G-buffer `g`) is under `target`, or [`MAX_SPP`] is reached.
/// `progress(spp, noise)` after each pass.
pub fn trace(
    scene: &crate::scene::Scene,
    g: &Readback,
    shadows: &ShadowMaps,
    target: f64,
    seed: u64,
    bounces: Bounces,
    progress: impl Fn(u32, f64),
) -> Truth {
    let pass = |spp: u32, s: u64| {
        crate::pathtrace::render(
            scene,
            &crate::pathtrace::PathTraceSettings {
                width: g.width,
                height: g.height,
                spp,
                seed: s,
                exposure: 1.0,
                bounces,
            },
            |_, _| {},
        )
    };
    // Seeds: the frame's, then two per pass, one per half.
    let mut next_seed = seed.wrapping_mul(1 << 20);
    let mut seeds = || {
        next_seed += 1;
        next_seed
    };
    let mut halves = Halves {
        a: pass(FIRST_SPP, seeds()),
        b: pass(FIRST_SPP, seeds()),
        spp: FIRST_SPP,
    };
    let mask = truth_mask(g, &halves.a.direct, shadows);
    // The noise of the image of every bounce count it serves (1, 2, 3,
    // all): the truth of fewer bounces is the sum of its first layers, and
    // must be under the target too.
    let noises = |h: &Halves| -> Vec<f64> {
        (1..=bounces.layers())
            .map(|n| h.noise(&mask.mask, n))
            .collect()
    };
    let worst = |n: &[f64]| n.iter().copied().fold(0.0, f64::max);
    let mut each = noises(&halves);
    let mut noise = worst(&each);
    progress(2 * halves.spp, noise);
    while noise > target && 2 * halves.spp < MAX_SPP {
        // Noise falls as 1/sqrt(spp): aim a little past the target.
        let want = (halves.spp as f64 * (noise / target).powi(2) * 1.2).ceil() as u32;
        let more = want
            .min(MAX_SPP / 2)
            .saturating_sub(halves.spp)
            .max(FIRST_SPP);
        let (a, b) = (pass(more, seeds()), pass(more, seeds()));
        halves.add(a, b, more);
        each = noises(&halves);
        noise = worst(&each);
        progress(2 * halves.spp, noise);
    }
    let spp = 2 * halves.spp;
    Truth {
        image: halves.mean(),
        bounces,
        mask,
        spp,
        noise: *each.last().unwrap_or(&noise),
        noises: each,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::readback::RsmReadback;
    use glam::Mat4;

    const W: u32 = 64;

    /// A floor seen from above, 0.25 m a pixel: x from -8 to 8 m, depth 10
    /// m, normal up; a step up (a ledge, depth 9 m) from column 48 on.
    fn floor() -> Readback {
        let n = (W * W) as usize;
        let mut position = vec![[0.0; 4]; n];
        let mut normal = vec![[0.0, 1.0, 0.0, 0.0]; n];
        for k in 0..n {
            let (x, y) = ((k as u32 % W) as f32, (k as u32 / W) as f32);
            let ledge = x >= 48.0;
            position[k] = [
                -8.0 + 0.25 * (x + 0.5),
                if ledge { 1.0 } else { 0.0 },
                -8.0 + 0.25 * (y + 0.5),
                if ledge { 9.0 } else { 10.0 },
            ];
            normal[k][3] = 0.0;
        }
        let empty = vec![[0.0; 4]; n];
        Readback {
            width: W,
            height: W,
            final_radiance: empty.clone(),
            direct: empty.clone(),
            indirect: empty.clone(),
            bounces: vec![],
            albedo: empty,
            normal,
            position,
            display: vec![],
            rsm: RsmReadback {
                resolution: 0,
                position: vec![],
                normal: vec![],
                flux: vec![],
            },
        }
    }

    /// A sun straight down whose shadow map of `r` texels spans the floor's 16 m.
    fn sun_view() -> LightView {
        // World x, z in [-8, 8] to clip [-1, 1]; depth unused here.
        let view_proj = Mat4::from_cols_array(&[
            1.0 / 8.0,
            0.0,
            0.0,
            0.0, //
            0.0,
            0.0,
            0.01,
            0.0, //
            0.0,
            1.0 / 8.0,
            0.0,
            0.0, //
            0.0,
            0.0,
            0.5,
            1.0,
        ]);
        LightView {
            light: 0,
            kind: LightKind::Directional,
            face: None,
            view_proj,
            position: Vec3::ZERO,
            direction: -Vec3::Y,
            half_extent: 8.0,
            depth_range: 10.0,
            cube: [Mat4::ZERO; 6],
            shadow: crate::view::ShadowFrustum::of_rsm(view_proj, 8.0),
        }
    }

    /// Exact direct light: lit left of column 24, shadowed right of it.
    fn shadowed_right() -> Vec<[f32; 4]> {
        (0..W * W)
            .map(|k| if k % W < 24 { [1.0; 4] } else { [0.0; 4] })
            .collect()
    }

    /// The columns of row 32 the mask keeps.
    fn kept_columns(r: u32) -> Vec<u32> {
        let views = [sun_view()];
        let shadows = ShadowMaps::new(&views, DVec3::ZERO, r, 1.0);
        let m = truth_mask(&floor(), &shadowed_right(), &shadows);
        (0..W).filter(|&x| m.mask[(32 * W + x) as usize]).collect()
    }

    #[test]
    fn geometric_edges_are_left_out_grown_by_a_pixel_and_shadow_edges_by_pcf_texels() {
        // Shadow map 64: a texel is a pixel (0.25 m), the band 2.5 texels; 16:
        // a texel is 4 pixels, the band 10 pixels.
        for (r, band) in [(64, 2.5f32), (16, 10.0)] {
            let kept = kept_columns(r);
            for x in 0..W {
                // Pixel centres against the shadow edge at x = 24 (between
                // columns 23 and 24, measured from the edge pixels' centres).
                let from_edge = if x < 24 { 23 - x } else { x - 24 } as f32;
                let near_shadow = from_edge <= band;
                let near_step = (46..=49).contains(&x);
                assert_eq!(
                    kept.contains(&x),
                    !near_shadow && !near_step,
                    "shadow map {r}: column {x} (kept: {kept:?})"
                );
            }
        }
    }

    #[test]
    fn a_smoothly_curved_surface_is_not_an_edge() {
        // A cylinder along z seen from above: the normal turns 3 degrees a
        // pixel, as a column's does, but has no kink.
        let mut g = floor();
        for k in 0..(W * W) as usize {
            let a = ((k as u32 % W) as f32 - 32.0) * 3f32.to_radians();
            g.normal[k] = [a.sin(), a.cos(), 0.0, 0.0];
            g.position[k][1] = 0.0;
            g.position[k][3] = 10.0;
        }
        let views = [sun_view()];
        let shadows = ShadowMaps::new(&views, DVec3::ZERO, 64, 1.0);
        let lit = vec![[1.0; 4]; (W * W) as usize];
        let m = truth_mask(&g, &lit, &shadows);
        assert_eq!(m.geometric_edges, 0);
        assert_eq!(m.shadow_edges, 0);
        assert_eq!(m.left_out(), 0.0);
    }
}
