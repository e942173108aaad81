//! Comparing with the path-traced truth (docs/algorithm.md section 6.6): the
//! pixels where a rasterizer and a path tracer can be compared at all.
//!
//! Two kinds of pixel differ by construction, whatever the radiometry:
//! - geometric edges: the rasterizer samples the pixel's centre, the path
//!   tracer averages over the pixel, so where normals or depths jump their
//!   coverage differs;
//! - direct-light shadow edges: percentage-closer filtering blurs a shadow
//!   over its filter's footprint in the shadow map, the path tracer's
//!   shadows are exact. The footprint is measured in RSM texels, so the band
//!   is found in the light's view, not the camera's: at a grazing light one
//!   texel can span many pixels.

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
    pub resolution: u32,
    /// Half-width of the band PCF may blur (RSM texels): its taps' spacing
    /// plus the hardware 2x2 compare's texel, plus half a texel for where
    /// the shadow map rasterised the occluder's edge.
    pub band_texels: f32,
}

impl<'a> ShadowMaps<'a> {
    /// `pcf_radius`: the PCF tap spacing in texels (`RenderSettings`).
    pub fn new(views: &'a [LightView], origin: DVec3, resolution: u32, pcf_radius: f32) -> Self {
        ShadowMaps {
            views,
            origin,
            resolution,
            band_texels: pcf_radius + 1.5,
        }
    }

    /// Texel coordinates of world point `p` in view `v`, if in front of it.
    fn texel(&self, v: &LightView, p: Vec3) -> Option<Vec2> {
        let rel = (p.as_dvec3() - self.origin).as_vec3();
        let clip = v.view_proj * rel.extend(1.0);
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
