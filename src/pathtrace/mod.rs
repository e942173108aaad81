//! Method `pathtrace` (docs/algorithm.md sections 1 and 5): a diffuse
//! reference WITH indirect visibility, on the CPU (all cores, rayon), from the
//! same lights (every light of the scene: spot, point, directional), camera
//! and materials as the rasterizer. It shows the error
//! that ignoring indirect visibility causes, which every VPL method shares.
//!
//! Per pixel, the primary ray goes through the pixel centre (as the G-buffer
//! samples it), so the direct layer is noise-free:
//!   L_direct(x) = sum over lights of rho/pi * I(w) * max(0, n.l) / r^2 * V
//!   (spot, point; directional: rho/pi * E * max(0, n.l) * V; exact V by a shadow ray)
//! Indirect irradiance by cosine-weighted hemisphere sampling, `spp` rays:
//!   E(x) = integral of L_direct(y(w)) cos dw ~= pi / N * sum_k L_direct(y_k)
//! where y_k is the nearest surface along sample k (occlusion included): one
//! bounce, the default. With `--bounces N` (`bounces`) each sample goes on
//! from y_k as a path, adding the light of bounces 2 to N (section 5.4,
//! "Bounces"), kept by bounce in layers of their own. The layers mean what
//! the rasterizer's mean (section 2): `indirect` is E, all bounces together.

pub mod bvh;
pub mod light_seen;

use crate::bounces::Bounces;
use crate::readback::{Readback, RsmReadback};
use crate::scene::{Light, LightKind, Scene};
use bvh::{Bvh, Cull, Triangle};
use glam::{Mat4, Vec2, Vec3, Vec3A, Vec4};
use rayon::prelude::*;
use std::f32::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Materials as the path tracer shades them: albedo factor and optional
/// texture. Geometry and lights are held relative to `origin` (the camera),
/// in f32 made from f64, so that a scene far from the world's origin keeps
/// the precision it has at the origin.
struct Shading<'a> {
    scene: &'a Scene,
    /// The scene's textures as the GPU samples them (a texture larger than
    /// a texture array's layer shrunk as it is for the GPU,
    /// `frame::texture_arrays::fitted`), so that both see the same texels.
    textures: Vec<std::borrow::Cow<'a, crate::scene::Texture>>,
    bvh: Bvh,
    /// The lights, their positions relative to `origin`.
    lights: Vec<Light>,
    origin: glam::DVec3,
}

/// How far a ray starts off the surface at `p` (relative to the camera):
/// many times the f32 rounding of `p`'s coordinates, whatever the scene's
/// size or place. A fixed share of the scene's extent was 9 m once one
/// object stood 500 km away, and every ray left the room (issue 29).
fn ray_offset(p: Vec3A) -> f32 {
    (p.abs().max_element() * 2e-6).max(f32::MIN_POSITIVE * 1e6)
}

/// The scene's surfaces as occluders between two surface points, with the
/// path tracer's BVH and its rules: what blocks a bounce ray blocks the
/// segment (back faces of single-sided surfaces do not), and positions are
/// taken relative to the camera as the path tracer's are (issue 25:
/// `visibility` tests VPL-to-receiver visibility with it).
pub struct Occluders<'a> {
    shading: Shading<'a>,
}

impl<'a> Occluders<'a> {
    /// `scene` as posed for the frame.
    pub fn new(scene: &'a Scene) -> Self {
        Occluders {
            shading: Shading::new(scene),
        }
    }

    /// Whether the surface point `to` (world space) is seen from the
    /// surface point `from` with normal `n_from`: no surface lies between
    /// them, the ray leaving `from` just off its surface and stopping just
    /// short of `to` (each by the offset of its coordinates' rounding).
    pub fn visible(&self, from: Vec3, n_from: Vec3, to: Vec3) -> bool {
        let origin = self.shading.origin;
        let rel = |p: Vec3| Vec3A::from((p.as_dvec3() - origin).as_vec3());
        let (a, b) = (rel(from), rel(to));
        let offset = ray_offset(a);
        let start = a + Vec3A::from(n_from) * offset;
        let v = b - start;
        let d = v.length();
        let end = d - 2.0 * ray_offset(b) - 1e-4 * d;
        if !(d > 0.0 && end > offset) {
            return true;
        }
        self.shading
            .bvh
            .intersect(start, v / d, offset, end, true, Cull::BackFaces)
            .is_none()
    }
}

/// A small, fast generator (PCG32) seeded per pixel, so results do not depend
/// on the thread schedule.
struct Pcg(u64);

impl Pcg {
    fn new(seed: u64, stream: u64) -> Self {
        let mut p = Pcg(seed.wrapping_add(stream.wrapping_mul(0x9E37_79B9_7F4A_7C15)));
        p.next();
        p.next();
        p
    }

    fn next(&mut self) -> u32 {
        let old = self.0;
        self.0 = old
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// Uniform in [0, 1).
    fn uniform(&mut self) -> f32 {
        (self.next() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }
}

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A surface point found by a ray.
struct SurfacePoint {
    position: Vec3A,
    /// Shading normal, turned to the side the ray came from for back faces of
    /// double-sided materials (as the rasterizer's `facing_normal`).
    normal: Vec3A,
    albedo: Vec3,
}

impl Shading<'_> {
    fn new(scene: &Scene) -> Shading<'_> {
        let origin = scene.camera.position().as_dvec3();
        let mut triangles = Vec::new();
        for inst in &scene.instances {
            let mesh = &scene.meshes[inst.mesh];
            let m = inst.world_from_object;
            let relative = inst.world_from_object.as_dmat4();
            let normal_matrix = Mat4::from_mat3(glam::Mat3::from_mat4(m).inverse().transpose());
            let double_sided = scene.materials[mesh.material].double_sided;
            for t in mesh.indices.chunks_exact(3) {
                let v = |k: usize| &mesh.vertices[t[k] as usize];
                triangles.push(Triangle {
                    p: std::array::from_fn(|k| {
                        let p = relative.transform_point3(Vec3::from(v(k).position).as_dvec3());
                        Vec3A::from((p - origin).as_vec3())
                    }),
                    n: std::array::from_fn(|k| {
                        Vec3A::from(normal_matrix.transform_vector3(Vec3::from(v(k).normal)))
                            .normalize_or_zero()
                    }),
                    uv: std::array::from_fn(|k| v(k).uv),
                    material: mesh.material as u32,
                    double_sided,
                });
            }
        }
        let lights = scene
            .lights
            .iter()
            .map(|l| Light {
                position: (l.position.as_dvec3() - origin).as_vec3(),
                ..*l
            })
            .collect();
        Shading {
            scene,
            textures: crate::frame::texture_arrays::fitted(&scene.textures),
            bvh: Bvh::new(triangles),
            lights,
            origin,
        }
    }

    fn texture(&self, index: usize, uv: Vec2) -> Vec3 {
        let t = &self.textures[index];
        // Bilinear with repeat, on linear values, texel centres at
        // (i + 0.5) / size, as shaders/material.glsl filters
        // (docs/algorithm.md section 3, step 1).
        let (w, h) = (t.width as f32, t.height as f32);
        let x = uv.x * w - 0.5;
        let y = uv.y * h - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let texel = |xi: f32, yi: f32| {
            let xi = (xi as i64).rem_euclid(t.width as i64) as usize;
            let yi = (yi as i64).rem_euclid(t.height as i64) as usize;
            let o = 4 * (yi * t.width as usize + xi);
            Vec3::new(
                srgb_to_linear(t.rgba8[o]),
                srgb_to_linear(t.rgba8[o + 1]),
                srgb_to_linear(t.rgba8[o + 2]),
            )
        };
        let top = texel(x0, y0).lerp(texel(x0 + 1.0, y0), fx);
        let bottom = texel(x0, y0 + 1.0).lerp(texel(x0 + 1.0, y0 + 1.0), fx);
        top.lerp(bottom, fy)
    }

    fn trace(&self, origin: Vec3A, dir: Vec3A) -> Option<SurfacePoint> {
        let hit = self.bvh.intersect(
            origin,
            dir,
            ray_offset(origin),
            f32::INFINITY,
            false,
            Cull::BackFaces,
        )?;
        let tri = &self.bvh.triangles[hit.triangle as usize];
        let w = 1.0 - hit.u - hit.v;
        let mut normal = (tri.n[0] * w + tri.n[1] * hit.u + tri.n[2] * hit.v).normalize_or_zero();
        let geometric = (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]);
        if geometric.dot(dir) > 0.0 {
            normal = -normal; // a back face (double-sided materials only reach here)
        }
        let material = &self.scene.materials[tri.material as usize];
        let uv = Vec2::from(tri.uv[0]) * w
            + Vec2::from(tri.uv[1]) * hit.u
            + Vec2::from(tri.uv[2]) * hit.v;
        let mut albedo = material.base_color.truncate();
        if let Some(t) = material.texture {
            albedo *= self.texture(t, uv);
        }
        Some(SurfacePoint {
            position: origin + dir * hit.t,
            normal,
            albedo,
        })
    }

    /// Radiance leaving `s` (Lambertian) from every light, shadow rays included.
    fn direct(&self, s: &SurfacePoint) -> Vec3 {
        self.lights.iter().map(|l| self.direct_from(l, s)).sum()
    }

    /// Radiance leaving `s` from `light`: a shadow ray to the light's
    /// position, or toward a directional light without end.
    fn direct_from(&self, light: &Light, s: &SurfacePoint) -> Vec3 {
        let (l, r, r2) = if light.kind == LightKind::Directional {
            (
                -Vec3A::from(light.direction).normalize(),
                f32::INFINITY,
                1.0,
            )
        } else {
            let to_light = Vec3A::from(light.position) - s.position;
            let r2 = to_light.length_squared();
            let r = r2.sqrt();
            (to_light / r, r, r2)
        };
        let cos = s.normal.dot(l);
        if cos <= 0.0 || r2 == 0.0 || !cos.is_finite() {
            return Vec3::ZERO;
        }
        // Both relative to `origin`, as the lights here are.
        let at = Vec3::from(s.position).as_dvec3();
        // W/sr for spot and point lights, E (W/m^2) for directional ones (r2 = 1).
        let intensity = if light.kind == LightKind::Directional {
            light.irradiance_facing(at).as_vec3()
        } else {
            light.intensity_toward(at).as_vec3()
        };
        if intensity.max_element() <= 0.0 {
            return Vec3::ZERO;
        }
        let offset = ray_offset(s.position);
        let origin = s.position + s.normal * offset;
        // Towards the light: blocked by faces turned to the light, as in the RSM.
        if self
            .bvh
            .intersect(origin, l, offset, r * (1.0 - 1e-4), true, Cull::FrontFaces)
            .is_some()
        {
            return Vec3::ZERO;
        }
        s.albedo / PI * intensity * cos / r2
    }

    /// The surface seen from `s` in a cosine-weighted direction drawn from
    /// `rng` (two uniforms), if any.
    fn bounce(&self, s: &SurfacePoint, rng: &mut Pcg) -> Option<SurfacePoint> {
        let n = s.normal;
        // An orthonormal basis around n (Duff et al. 2017).
        let sign = 1f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let t = Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let bt = Vec3A::new(b, sign + n.y * n.y * a, -n.y);
        let origin = s.position + n * ray_offset(s.position);
        let (u1, u2) = (rng.uniform(), rng.uniform());
        let r = u1.sqrt();
        let phi = 2.0 * PI * u2;
        let dir = (t * (r * phi.cos()) + bt * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt())
            .normalize();
        self.trace(origin, dir)
    }

    /// Indirect irradiance at `s` from `spp` paths of up to `bounces`
    /// bounces, by bounce: bounces 1, 2, 3, and 4 to the last
    /// (docs/algorithm.md section 5.4, "Bounces"). Bounce k of a path that
    /// reached `y_1 ... y_k` adds `pi rho(y_1) ... rho(y_k-1) L_direct(y_k)`
    /// (cosine-weighted directions: the pdf's `cos / pi` cancels the
    /// cosine), so the sum over bounces estimates the Neumann series.
    fn indirect(
        &self,
        s: &SurfacePoint,
        spp: u32,
        bounces: Bounces,
        rng: &mut Pcg,
    ) -> [Vec3; LAYERS] {
        let mut sums = [Vec3::ZERO; LAYERS];
        self.paths(s, spp, bounces, rng, |k, _, light| {
            sums[(k as usize).min(LAYERS) - 1] += light;
        });
        sums.map(|sum| sum * (PI / spp as f32))
    }

    /// The paths of `indirect`: `visit(k, y_k, light)` for every vertex
    /// `y_k` a path reaches, in order, `light` its bounce-k term before the
    /// `pi / spp` (`light_seen` classifies the paths by their vertices).
    fn paths(
        &self,
        s: &SurfacePoint,
        spp: u32,
        bounces: Bounces,
        rng: &mut Pcg,
        mut visit: impl FnMut(u32, &SurfacePoint, Vec3),
    ) {
        let last = bounces.last();
        for _ in 0..spp {
            // With one bounce this draws and adds exactly as the one-bounce
            // estimator before it, so a one-bounce image (and every truth
            // cached from one) is unchanged bit for bit.
            let Some(mut y) = self.bounce(s, rng) else {
                continue;
            };
            let mut weight = Vec3::ONE;
            let mut k = 1;
            loop {
                visit(k, &y, weight * self.direct(&y));
                if last == Some(k) {
                    break;
                }
                weight *= y.albedo;
                // Russian roulette from the fourth bounce on: the path goes
                // on with probability p = min(max albedo of y, 0.95) and its
                // weight is divided by p, so the estimate is unbiased. Taking
                // p from the albedo keeps the surviving weight's factor
                // rho / p at most 1 (roulette adds no fireflies) and ends
                // paths soon in dark scenes; the 0.95 cap ends them in a
                // white room too (at most 20 bounces more on average), so
                // `inf` is finite. Bounces 1 to 3 are traced in full: their
                // layers carry no roulette noise.
                if k >= LAYERS as u32 - 1 {
                    let p = y.albedo.max_element().min(MAX_SURVIVAL);
                    if rng.uniform() >= p {
                        break;
                    }
                    weight /= p;
                }
                if weight.max_element() <= 0.0 {
                    break; // a black surface reflects no further bounce
                }
                match self.bounce(&y, rng) {
                    Some(next) => y = next,
                    None => break,
                }
                k += 1;
            }
        }
    }
}

/// The path tracer's layers of indirect light by bounce (`bounces::LAYERS`).
const LAYERS: usize = crate::bounces::LAYERS.len();

/// The largest probability with which Russian roulette lets a path go on
/// (see `indirect`).
const MAX_SURVIVAL: f32 = 0.95;

/// What `render` needs besides the scene.
/// Its name on the command line: `isr render --method pathtrace` runs it
/// instead of a GPU method (it is not in the GPU methods' registry).
pub const NAME: &str = "pathtrace";

/// Its line in `--method`'s help.
pub const HELP: &str =
    "Path tracing with indirect visibility (one bounce, or --bounces), on the CPU (isr render only).";

#[derive(Clone, Debug)]
pub struct PathTraceSettings {
    pub width: u32,
    pub height: u32,
    /// Indirect samples per pixel.
    pub spp: u32,
    pub seed: u64,
    pub exposure: f32,
    /// Bounces of indirect light (`--bounces`): one, as the GPU methods.
    pub bounces: Bounces,
}

/// Renders `scene`; `progress(rows_done, rows)` is called from a helper thread
/// about four times a second. The RSM part of the result is empty.
pub fn render(
    scene: &Scene,
    s: &PathTraceSettings,
    progress: impl Fn(usize, usize) + Sync,
) -> Readback {
    let shading = Shading::new(scene);
    // Rays in the shading's frame: the camera at its origin.
    let at_origin = crate::scene::Camera {
        world_from_camera: Mat4::from_quat(glam::Quat::from_mat4(&scene.camera.world_from_camera)),
        ..scene.camera
    };
    let clip_to_world = crate::view::camera_view_proj(&at_origin, s.width, s.height).inverse();
    let eye = Vec3A::ZERO;
    let forward = Vec3A::from(scene.camera.forward());
    let world_origin = shading.origin;
    let (w, h) = (s.width as usize, s.height as usize);
    // final, direct, indirect, albedo, normal, position, then the bounces'.
    let mut pixels = vec![[[0f32; 4]; 6 + LAYERS]; w * h];
    let rows_done = AtomicUsize::new(0);
    std::thread::scope(|scope| {
        let done = &rows_done;
        let reporter = scope.spawn(|| loop {
            let d = done.load(Ordering::Relaxed);
            progress(d, h);
            if d >= h {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(250));
        });
        pixels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                // Through the pixel centre, as the rasterizer samples it.
                let ndc = Vec4::new(
                    2.0 * (x as f32 + 0.5) / s.width as f32 - 1.0,
                    2.0 * (y as f32 + 0.5) / s.height as f32 - 1.0,
                    1.0, // the near plane in reversed-Z
                    1.0,
                );
                let p = clip_to_world * ndc;
                // From the near plane, which the rasterizer clips at.
                let near = Vec3A::from(p.truncate() / p.w);
                let dir = (near - eye).normalize();
                let Some(hit) = shading.trace(near, dir) else {
                    continue;
                };
                let mut rng = Pcg::new(s.seed, (y * w + x) as u64);
                let direct = shading.direct(&hit);
                let by_bounce = shading.indirect(&hit, s.spp, s.bounces, &mut rng);
                // Everything after the first hit's direct light: the
                // bounces' sum (those not traced are 0).
                let indirect: Vec3 = by_bounce.iter().sum();
                let final_radiance = direct + hit.albedo / PI * indirect;
                let depth = (hit.position - eye).dot(forward).max(f32::MIN_POSITIVE);
                let position = (Vec3::from(hit.position).as_dvec3() + world_origin).as_vec3();
                let rgb = |v: Vec3| v.extend(1.0).to_array();
                let [b1, b2, b3, b4] = by_bounce.map(rgb);
                *out = [
                    rgb(final_radiance),
                    rgb(direct),
                    rgb(indirect),
                    rgb(hit.albedo),
                    Vec3::from(hit.normal).extend(0.0).to_array(),
                    position.extend(depth).to_array(),
                    b1,
                    b2,
                    b3,
                    b4,
                ];
            }
            done.fetch_add(1, Ordering::Relaxed);
        });
        let _ = reporter.join();
    });
    let layer = |k: usize| pixels.iter().map(|p| p[k]).collect::<Vec<_>>();
    let final_radiance = layer(0);
    let display = final_radiance
        .iter()
        .flat_map(|c| {
            let e = |v: f32| crate::debug_view::srgb(v * s.exposure);
            [e(c[0]), e(c[1]), e(c[2]), 255]
        })
        .collect();
    Readback {
        width: s.width,
        height: s.height,
        final_radiance,
        direct: layer(1),
        indirect: layer(2),
        // The layers this run traced: bounces beyond its last hold nothing.
        bounces: (0..s.bounces.layers()).map(|k| layer(6 + k)).collect(),
        albedo: layer(3),
        normal: layer(4),
        position: layer(5),
        display,
        rsm: RsmReadback {
            resolution: 0,
            position: vec![],
            normal: vec![],
            flux: vec![],
        },
    }
}

#[cfg(test)]
mod tests;
