//! Scenes: triangle meshes placed by transforms, diffuse materials, a list
//! of lights (spot, point, directional) and one perspective camera. Loaded from glTF (`gltf_load`),
//! Wavefront OBJ (`obj_load`) or a scene description naming either
//! (`description`), all through [`load_file`]; built in (`cornell`), or
//! assembled by code (tests) with the helpers below.

mod accessor;
pub mod animation;
pub mod cornell;
pub mod description;
pub mod export;
pub mod gltf_load;
pub mod limits;
pub mod motion;
pub mod obj_load;
mod texture_decode;
mod uri;

pub use gltf_load::LoadOptions;

/// What kind of scene file a path names, by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// `.obj`: Wavefront OBJ (+ MTL).
    Obj,
    /// `.json` (`NAME.scene.json`): a scene description naming a mesh.
    Description,
    /// `.gltf`, `.glb` and anything else: glTF (the loader reads the GLB
    /// magic or the JSON and says what is wrong with other files).
    Gltf,
}

impl FileKind {
    pub fn of(path: &std::path::Path) -> FileKind {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("obj") => FileKind::Obj,
            Some("json") => FileKind::Description,
            _ => FileKind::Gltf,
        }
    }
}

/// Loads the scene file `path` with the loader its extension names
/// ([`FileKind`]): glTF, OBJ or a scene description, each under the same
/// policy and budgets (`options`; docs/security.md).
pub fn load_file(path: &std::path::Path, options: &LoadOptions) -> anyhow::Result<Scene> {
    match FileKind::of(path) {
        FileKind::Obj => obj_load::load_with(path, options),
        FileKind::Description => description::load_with(path, options),
        FileKind::Gltf => gltf_load::load_with(path, options),
    }
}

use glam::{Mat4, Vec2, Vec3, Vec4};

/// One vertex as the vertex shaders read it (`shaders/scene.vert`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
}

impl GpuVertex {
    pub fn attributes() -> [ash::vk::VertexInputAttributeDescription; 3] {
        use ash::vk;
        let attr = |location, format, offset| vk::VertexInputAttributeDescription {
            location,
            binding: 0,
            format,
            offset: offset as u32,
        };
        [
            attr(
                0,
                vk::Format::R32G32B32_SFLOAT,
                std::mem::offset_of!(Self, position),
            ),
            attr(
                1,
                vk::Format::R32G32B32_SFLOAT,
                std::mem::offset_of!(Self, normal),
            ),
            attr(2, vk::Format::R32G32_SFLOAT, std::mem::offset_of!(Self, uv)),
        ]
    }
}

#[derive(Clone, Debug)]
pub struct Mesh {
    pub name: String,
    pub vertices: Vec<GpuVertex>,
    pub indices: Vec<u32>,
    pub material: usize,
}

/// A mesh placed in the world.
#[derive(Clone, Debug)]
pub struct Instance {
    pub mesh: usize,
    pub world_from_object: Mat4,
}

#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    /// Linear diffuse albedo (glTF `baseColorFactor`), multiplied by the texture.
    pub base_color: Vec4,
    /// Index into `Scene::textures` (glTF `baseColorTexture`, sRGB).
    pub texture: Option<usize>,
    /// Single-sided materials are back-face culled, as glTF specifies.
    pub double_sided: bool,
}

#[derive(Clone, Debug)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// sRGB-encoded RGBA8, rows top to bottom.
    pub rgba8: Vec<u8>,
}

/// What kind of `KHR_lights_punctual` light (docs/algorithm.md section 2.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightKind {
    /// A cone: intensity in candela (W/sr), the cones below apply.
    #[default]
    Spot,
    /// All around: intensity in candela (W/sr); the cones are ignored.
    Point,
    /// Parallel rays along `direction`: intensity in lux, read as the
    /// irradiance E (W/m^2) on a surface facing the light; position, cones
    /// and range are ignored.
    Directional,
}

impl LightKind {
    pub fn name(self) -> &'static str {
        match self {
            LightKind::Spot => "spot",
            LightKind::Point => "point",
            LightKind::Directional => "directional",
        }
    }
}

/// A `KHR_lights_punctual` light (docs/algorithm.md sections 2.3 and 2.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    pub position: Vec3,
    /// Unit vector the cone (or the directional light's rays) points along (the node's -Z).
    pub direction: Vec3,
    /// Linear RGB color.
    pub color: Vec3,
    /// Spot and point: luminous intensity in candela, treated as W/sr.
    /// Directional: illuminance in lux, treated as irradiance E in W/m^2.
    pub intensity: f32,
    /// Radians; attenuation is smooth between inner and outer (spot lights only).
    pub inner_cone: f32,
    pub outer_cone: f32,
    /// Distance cut-off; `None` means none (the extension's default).
    pub range: Option<f32>,
}

/// The name most of the code knew the light by, when spot lights were all there was.
pub type SpotLight = Light;

impl Light {
    /// The extension's angular attenuation, squared smoothstep between the
    /// cones; 1 for point and directional lights.
    pub fn angular_attenuation(&self, cos_angle: f64) -> f64 {
        if self.kind != LightKind::Spot {
            return 1.0;
        }
        let (scale, offset) = self.cone_scale_offset();
        let t = (cos_angle * scale as f64 + offset as f64).clamp(0.0, 1.0);
        t * t
    }

    /// `lightAngleScale` and `lightAngleOffset` as KHR_lights_punctual defines them.
    pub fn cone_scale_offset(&self) -> (f32, f32) {
        let cos_outer = self.outer_cone.cos();
        let cos_inner = self.inner_cone.cos();
        let scale = 1.0 / (cos_inner - cos_outer).max(0.001);
        (scale, -cos_outer * scale)
    }

    /// Radiant intensity (W/sr) toward world point `p`, per color channel,
    /// including the range window when a range is set. Spot and point lights.
    pub fn intensity_toward(&self, p: glam::DVec3) -> glam::DVec3 {
        let to = p - self.position.as_dvec3();
        let d = to.length();
        let cos = to.dot(self.direction.as_dvec3()) / d;
        let mut i = self.color.as_dvec3() * self.intensity as f64 * self.angular_attenuation(cos);
        if let Some(range) = self.range {
            let r = d / range as f64;
            i *= (1.0 - r.powi(4)).clamp(0.0, 1.0);
        }
        i
    }

    /// Irradiance (W/m^2, per channel) on a surface at `p` facing the light,
    /// unshadowed: `I(w) / d^2` for spot and point lights, `E` for directional
    /// ones (docs/algorithm.md section 2.4).
    pub fn irradiance_facing(&self, p: glam::DVec3) -> glam::DVec3 {
        match self.kind {
            LightKind::Directional => self.color.as_dvec3() * self.intensity as f64,
            _ => self.intensity_toward(p) / (p - self.position.as_dvec3()).length_squared(),
        }
    }

    /// Unit vector from `p` toward the light.
    pub fn direction_from(&self, p: glam::DVec3) -> glam::DVec3 {
        match self.kind {
            LightKind::Directional => -self.direction.as_dvec3().normalize(),
            _ => (self.position.as_dvec3() - p).normalize(),
        }
    }
}

/// A perspective camera looking down its local -Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Rotation and translation only ([`rigid`]): a camera's node may be
    /// scaled (a scene scaled as a whole scales its camera's node too), but
    /// its field of view and znear are its own, so the view is the node's
    /// placement without the scale.
    pub world_from_camera: Mat4,
    /// Vertical field of view, radians.
    pub yfov: f32,
    pub znear: f32,
}

impl Camera {
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, yfov: f32, znear: f32) -> Self {
        Self {
            world_from_camera: Mat4::look_at_rh(eye, target, up).inverse(),
            yfov,
            znear,
        }
    }

    pub fn position(&self) -> Vec3 {
        self.world_from_camera.w_axis.truncate()
    }

    pub fn forward(&self) -> Vec3 {
        (-self.world_from_camera.z_axis.truncate()).normalize()
    }
}

/// The rotation and translation of `m`, without its scale: `None` when `m`
/// is not finite or maps some direction to (nearly) zero (a scale of 0),
/// so that it has no orientation.
pub fn rigid(m: Mat4) -> Option<Mat4> {
    let l = glam::Mat3::from_mat4(m);
    let lengths = l.x_axis.length() * l.y_axis.length() * l.z_axis.length();
    let det = l.determinant();
    let regular =
        lengths.is_finite() && lengths > 0.0 && det.is_finite() && det.abs() > 1e-6 * lengths;
    if !(regular && m.w_axis.is_finite()) {
        return None;
    }
    let (_, rotation, translation) = m.to_scale_rotation_translation();
    rotation
        .is_finite()
        .then(|| Mat4::from_rotation_translation(rotation.normalize(), translation))
}

/// The origin the GPU renders relative to, for `camera`: its position
/// snapped to a grid whose cell is the power of two at or above 64 times
/// its znear ([`render_origin_cell`]). Positions on the GPU are then what
/// they would be with the camera near the world's origin, wherever the
/// scene is, and keep the precision they have there; the origin moves only
/// when the camera crosses a cell; and a scene moved by whole cells, or
/// scaled by a power of two (znear with it), renders from exactly the same
/// (or exactly scaled) numbers.
pub fn render_origin(camera: &Camera) -> glam::DVec3 {
    let cell = render_origin_cell(camera.znear);
    (camera.position().as_dvec3() / cell).round() * cell
}

/// See [`render_origin`]: the camera is then within 56 znear of the
/// origin, so geometry it sees (at least znear away) has relative
/// coordinates no more than about 57 times its distance, a loss of under
/// 6 bits of float precision at the nearest and less beyond.
pub fn render_origin_cell(znear: f32) -> f64 {
    let z = znear as f64 * 64.0;
    if !(z.is_finite() && z > 0.0) {
        return 1.0;
    }
    2f64.powi(z.log2().ceil() as i32)
}

/// What changes from frame to frame: where the camera and the light are and
/// where every mesh instance is. The renderer takes one per frame
/// (`Renderer::update`); nothing else about the scene changes between frames.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameState {
    pub camera: Camera,
    /// Every light of the scene, in `Scene::lights` order.
    pub lights: Vec<Light>,
    /// World transform of each `Scene::instances` entry, in the same order.
    pub instance_transforms: Vec<Mat4>,
}

impl FrameState {
    /// This state with every position taken relative to `origin` (computed
    /// in f64): what the GPU renders, so that a scene far from the world's
    /// origin keeps the precision it has near it (`render_origin`).
    pub fn relative_to(&self, origin: glam::DVec3) -> FrameState {
        if origin == glam::DVec3::ZERO {
            return self.clone();
        }
        let shift = |p: Vec3| (p.as_dvec3() - origin).as_vec3();
        let mut camera = self.camera;
        camera.world_from_camera.w_axis = shift(self.camera.position()).extend(1.0);
        let to_origin = glam::DMat4::from_translation(-origin);
        FrameState {
            camera,
            lights: self
                .lights
                .iter()
                .map(|l| Light {
                    position: shift(l.position),
                    ..*l
                })
                .collect(),
            instance_transforms: self
                .instance_transforms
                .iter()
                .map(|m| (to_origin * m.as_dmat4()).as_mat4())
                .collect(),
        }
    }

    /// `scene` posed in this state: its camera, lights and instance
    /// transforms replaced (what the CPU path tracer renders a frame from).
    pub fn pose(&self, scene: &Scene) -> Scene {
        let mut posed = scene.clone();
        posed.camera = self.camera;
        posed.lights = self.lights.clone();
        for (inst, m) in posed.instances.iter_mut().zip(&self.instance_transforms) {
            inst.world_from_object = *m;
        }
        posed
    }
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub meshes: Vec<Mesh>,
    pub instances: Vec<Instance>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    /// At least one light; each gets its own RSM and light tree.
    pub lights: Vec<Light>,
    pub camera: Camera,
    /// Things the loader skipped or assumed, printed by the CLI.
    pub warnings: Vec<String>,
    /// What moves over time; `None` for a still scene (and scenes built by code).
    pub animation: Option<animation::Animation>,
}

impl Scene {
    /// An empty scene with the given light and camera, for code that builds scenes.
    pub fn empty(name: &str, light: Light, camera: Camera) -> Self {
        Self {
            name: name.into(),
            meshes: vec![],
            instances: vec![],
            materials: vec![],
            textures: vec![],
            lights: vec![light],
            camera,
            warnings: vec![],
            animation: None,
        }
    }

    pub fn add_material(&mut self, name: &str, albedo: Vec3) -> usize {
        self.materials.push(Material {
            name: name.into(),
            base_color: albedo.extend(1.0),
            texture: None,
            double_sided: false,
        });
        self.materials.len() - 1
    }

    /// Adds a mesh with one instance at the identity transform.
    pub fn add_mesh(
        &mut self,
        name: &str,
        vertices: Vec<GpuVertex>,
        indices: Vec<u32>,
        material: usize,
    ) {
        self.meshes.push(Mesh {
            name: name.into(),
            vertices,
            indices,
            material,
        });
        self.instances.push(Instance {
            mesh: self.meshes.len() - 1,
            world_from_object: Mat4::IDENTITY,
        });
    }

    /// Adds the planar quad `corners` (counter-clockwise seen from its front).
    pub fn add_quad(&mut self, name: &str, corners: [Vec3; 4], material: usize) {
        let (v, i) = quad(corners);
        self.add_mesh(name, v, i, material);
    }

    /// World-space bounding box of all instances, or `None` for an empty scene.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for inst in &self.instances {
            for v in &self.meshes[inst.mesh].vertices {
                let p = inst
                    .world_from_object
                    .transform_point3(Vec3::from(v.position));
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }

    /// The scene as loaded: its camera, its light and every instance at its
    /// loaded transform.
    pub fn rest_state(&self) -> FrameState {
        FrameState {
            camera: self.camera,
            lights: self.lights.clone(),
            instance_transforms: self.instances.iter().map(|i| i.world_from_object).collect(),
        }
    }

    /// The state at animation time `t` seconds: `rest_state()` with what the
    /// animation moves moved (the same for every `t` without animation).
    pub fn state_at(&self, t: f32) -> FrameState {
        let mut state = self.rest_state();
        if let Some(a) = &self.animation {
            a.apply(t, &mut state);
        }
        state
    }

    /// [`Self::state_at`], checked for what the loader checks of the rest
    /// pose, since an animation can break it at some times only: the camera
    /// has an orientation (no NaN, no scale of 0), every light a finite
    /// place and direction, every moved instance a finite transform that
    /// keeps its mesh inside `limit` metres of the origin. The error names
    /// the time, what is wrong and the channels that move it.
    pub fn pose_at(&self, t: f32) -> anyhow::Result<FrameState> {
        self.pose_within(t, limits::Limits::DEFAULT.coordinate)
    }

    /// [`Self::pose_at`] with the coordinate limit `limit` (m).
    pub fn pose_within(&self, t: f32, limit: f32) -> anyhow::Result<FrameState> {
        use animation::Moved;
        let state = self.state_at(t);
        let Some(a) = &self.animation else {
            return Ok(state);
        };
        let fail = |what: Moved, problem: String| -> anyhow::Error {
            let channels = a.channels_moving(what, t);
            anyhow::anyhow!(
                "at t = {t} s {problem}; it is moved by {}",
                if channels.is_empty() {
                    "no channel (its rest pose)".to_string()
                } else {
                    channels.join(", ")
                }
            )
        };
        if rigid(state.camera.world_from_camera).is_none() {
            return Err(fail(
                Moved::Camera,
                "the camera has no orientation (its transform is not finite or scales to 0)".into(),
            ));
        }
        for (i, l) in state.lights.iter().enumerate() {
            if !(l.position.is_finite() && l.direction.is_finite()) {
                return Err(fail(
                    Moved::Light(i),
                    format!(
                        "light {i} is at {} facing {}, not finite",
                        l.position, l.direction
                    ),
                ));
            }
        }
        for &(i, _) in &a.instances {
            let (Some(inst), Some(m)) = (self.instances.get(i), state.instance_transforms.get(i))
            else {
                continue;
            };
            let mesh = &self.meshes[inst.mesh];
            let reach = mesh
                .vertices
                .iter()
                .map(|v| {
                    m.transform_point3(Vec3::from(v.position))
                        .abs()
                        .max_element()
                })
                .fold(0.0f32, |r, x| {
                    if x.is_nan() || r.is_nan() {
                        f32::NAN
                    } else {
                        r.max(x)
                    }
                });
            if !m.is_finite() || reach.is_nan() || reach > limit {
                return Err(fail(
                    Moved::Instance(i),
                    format!(
                        "instance {i} ({}) reaches {reach:.3e} m from the origin; isr supports coordinates up to {limit:.0e} m",
                        mesh.name
                    ),
                ));
            }
        }
        Ok(state)
    }

    /// The latest keyframe time, or `None` for a still scene.
    pub fn animation_duration(&self) -> Option<f32> {
        self.animation.as_ref().and_then(|a| a.duration())
    }

    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes[i.mesh].indices.len() / 3)
            .sum()
    }
}

/// Vertices and indices of a planar quad given counter-clockwise from its front.
pub fn quad(c: [Vec3; 4]) -> (Vec<GpuVertex>, Vec<u32>) {
    let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize();
    let uvs = [
        Vec2::new(0.0, 1.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(0.0, 0.0),
    ];
    let vertices = c
        .iter()
        .zip(uvs)
        .map(|(p, uv)| GpuVertex {
            position: p.to_array(),
            normal: n.to_array(),
            uv: uv.to_array(),
        })
        .collect();
    (vertices, vec![0, 1, 2, 0, 2, 3])
}

/// A closed box with outward faces: `center`, full `size`, turned by `yaw` radians about +Y.
pub fn cuboid(center: Vec3, size: Vec3, yaw: f32) -> (Vec<GpuVertex>, Vec<u32>) {
    let rot = glam::Quat::from_rotation_y(yaw);
    let h = size * 0.5;
    let corner = |x: f32, y: f32, z: f32| center + rot * Vec3::new(x * h.x, y * h.y, z * h.z);
    // Each face counter-clockwise seen from outside.
    let faces = [
        [
            corner(-1., -1., 1.),
            corner(1., -1., 1.),
            corner(1., 1., 1.),
            corner(-1., 1., 1.),
        ], // +z
        [
            corner(1., -1., -1.),
            corner(-1., -1., -1.),
            corner(-1., 1., -1.),
            corner(1., 1., -1.),
        ], // -z
        [
            corner(1., -1., 1.),
            corner(1., -1., -1.),
            corner(1., 1., -1.),
            corner(1., 1., 1.),
        ], // +x
        [
            corner(-1., -1., -1.),
            corner(-1., -1., 1.),
            corner(-1., 1., 1.),
            corner(-1., 1., -1.),
        ], // -x
        [
            corner(-1., 1., 1.),
            corner(1., 1., 1.),
            corner(1., 1., -1.),
            corner(-1., 1., -1.),
        ], // +y
        [
            corner(-1., -1., -1.),
            corner(1., -1., -1.),
            corner(1., -1., 1.),
            corner(-1., -1., 1.),
        ], // -y
    ];
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for f in faces {
        let (v, i) = quad(f);
        let base = vertices.len() as u32;
        vertices.extend(v);
        indices.extend(i.into_iter().map(|i| i + base));
    }
    (vertices, indices)
}

/// Face normals accumulated per vertex, for primitives without NORMAL.
/// The factor that scales `vertices` to about unit size (1 when they are
/// all at the origin or not finite), for cross products of their edges: at
/// 1e18 m one (1e36) would overflow when normalised. One scale for the
/// whole mesh keeps the area weights' ratios.
pub(crate) fn unit_scale(vertices: &[GpuVertex]) -> f32 {
    let extent = vertices
        .iter()
        .flat_map(|v| v.position)
        .fold(0f32, |m, c| m.max(c.abs()));
    if extent > 0.0 && extent.is_finite() {
        1.0 / extent
    } else {
        1.0
    }
}

pub fn compute_normals(vertices: &mut [GpuVertex], indices: &[u32]) {
    // Positions scaled to about unit size first (`unit_scale`).
    let scale = unit_scale(vertices);
    let mut acc = vec![Vec3::ZERO; vertices.len()];
    for t in indices.chunks_exact(3) {
        let p = |k: usize| Vec3::from(vertices[t[k] as usize].position) * scale;
        // Area-weighted: the cross product's length is twice the area.
        let n = (p(1) - p(0)).cross(p(2) - p(0));
        for &k in t {
            acc[k as usize] += n;
        }
    }
    for (v, n) in vertices.iter_mut().zip(acc) {
        v.normal = n.normalize_or(Vec3::Y).to_array();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_faces_point_outward() {
        let center = Vec3::new(0.3, 0.5, -0.2);
        let (v, i) = cuboid(center, Vec3::new(0.6, 1.0, 0.4), 0.7);
        for t in i.chunks_exact(3) {
            let p = |k: usize| Vec3::from(v[t[k] as usize].position);
            let n = (p(1) - p(0)).cross(p(2) - p(0));
            assert!(n.dot(p(0) - center) > 0.0, "face winding points inward");
            assert!(n
                .normalize()
                .abs_diff_eq(Vec3::from(v[t[0] as usize].normal), 1e-5));
        }
    }

    #[test]
    fn spot_attenuation_follows_khr_lights_punctual() {
        let l = SpotLight {
            kind: LightKind::Spot,
            position: Vec3::ZERO,
            direction: -Vec3::Y,
            color: Vec3::ONE,
            intensity: 1.0,
            inner_cone: 0.3,
            outer_cone: 0.6,
            range: None,
        };
        assert_eq!(l.angular_attenuation(1.0), 1.0);
        assert!((l.angular_attenuation(0.3f64.cos()) - 1.0).abs() < 1e-6);
        assert_eq!(l.angular_attenuation(0.7f64.cos()), 0.0);
        // Halfway in cosine between the cones: (1/2)^2.
        let mid = 0.5 * (0.3f64.cos() + 0.6f64.cos());
        assert!((l.angular_attenuation(mid) - 0.25).abs() < 1e-4);
    }

    #[test]
    fn computed_normals_of_a_flat_quad_are_its_normal() {
        let (mut v, i) = quad([Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, -1.0), -Vec3::Z]);
        for x in &mut v {
            x.normal = [0.0; 3];
        }
        compute_normals(&mut v, &i);
        assert!(v
            .iter()
            .all(|x| Vec3::from(x.normal).abs_diff_eq(Vec3::Y, 1e-6)));
    }
}
