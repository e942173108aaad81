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
pub mod fuzzing;
mod geometry;
pub mod gltf_load;
mod light_camera;
pub mod limits;
pub mod motion;
pub mod obj_load;
pub mod text;
mod texture_decode;
mod uri;

pub use geometry::{compute_normals, cuboid, direction, quad};
pub use gltf_load::LoadOptions;
pub use light_camera::{
    check_yfov, render_origin, render_origin_cell, rigid, Camera, Light, LightKind, SpotLight,
    MIN_YFOV,
};

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
///
/// Every message it returns (the error, the scene's warnings) is passed
/// through [`text::sanitize`]: whatever bytes of the file a message
/// quotes, none reaches the terminal raw, and none is longer than a few
/// lines.
pub fn load_file(path: &std::path::Path, options: &LoadOptions) -> anyhow::Result<Scene> {
    let loaded = match FileKind::of(path) {
        FileKind::Obj => obj_load::load_with(path, options),
        FileKind::Description => description::load_with(path, options),
        FileKind::Gltf => gltf_load::load_with(path, options),
    };
    match loaded {
        Ok(mut scene) => {
            for w in &mut scene.warnings {
                *w = text::sanitize(w);
            }
            Ok(scene)
        }
        Err(e) => Err(anyhow::anyhow!(text::sanitize(&format!("{e:#}")))),
    }
}

use glam::{Mat4, Vec3, Vec4};

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

/// The origin a loader stores a scene relative to ([`Scene::origin`]),
/// from its world bounds `lo`, `hi` (f64): zero for a scene whose centre is
/// within its own extent of the world's origin (every scene built around
/// it keeps its numbers, bit for bit), else its centre snapped to a grid
/// whose cell is the power of two at or above its extent. Relative to it,
/// positions are within an extent of zero and keep the precision they have
/// at home; snapped, a scene moved by whole cells gets the same numbers.
pub fn scene_origin(lo: glam::DVec3, hi: glam::DVec3) -> glam::DVec3 {
    let centre = (lo + hi) * 0.5;
    let extent = (hi - lo).max_element();
    if !(extent > 0.0 && centre.is_finite()) || centre.abs().max_element() <= extent {
        return glam::DVec3::ZERO;
    }
    let cell = 2f64.powi(extent.log2().ceil() as i32);
    (centre / cell).round() * cell
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
    /// Where the scene's coordinates start, in world metres: every
    /// position of the scene (vertices through their instances, lights,
    /// the camera, the animation) is relative to it. Zero unless a loader
    /// found the scene far from the world's origin for its size
    /// ([`scene_origin`]): it then composed the file's transforms in f64
    /// and subtracted this before rounding to f32, so that a scene moved
    /// by 9e5 m renders as it does at home. Budgets on coordinates count
    /// it in; the renderer never needs it (images do not depend on where
    /// the scene is).
    pub origin: glam::DVec3,
    /// Which of the light and the camera the loader made up because the
    /// file (an OBJ, a glTF without them) had none and no description gave
    /// them: the command line places those by looking at the scene
    /// (`placement`).
    pub bare: Bare,
}

/// See [`Scene::bare`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Bare {
    pub light: bool,
    pub camera: bool,
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
            origin: glam::DVec3::ZERO,
            bare: Bare::default(),
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
            // In world metres: the scene's origin counted in, in f64.
            let reach = mesh
                .vertices
                .iter()
                .map(|v| {
                    (self.origin + m.transform_point3(Vec3::from(v.position)).as_dvec3())
                        .abs()
                        .max_element() as f32
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
