//! The options `isr render` and `isr view` share ([`RunArgs`]: the scene, the
//! method and its parameters, the sizes, the device), flattened into both
//! commands; the method parameters (`method_args::ParamArgs`) are flattened into
//! `isr bench` too.

use crate::method_args::ParamArgs;
use crate::methods;
use crate::settings::{Method, RenderSettings};
use crate::vk::{GpuOptions, Validation};
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;

/// Every default below comes from `RenderSettings::DEFAULT`, which the
/// library and the benchmarks use too.
const D: RenderSettings = RenderSettings::DEFAULT;

/// What `--method` names: a GPU method of the registry, or the CPU path
/// tracer, which is a renderer of its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodArg {
    Gpu(Method),
    PathTrace,
}

impl MethodArg {
    pub fn name(self) -> &'static str {
        match self {
            MethodArg::Gpu(m) => m.name(),
            MethodArg::PathTrace => crate::pathtrace::NAME,
        }
    }
}

/// `--method`'s values, each with its help: the registry's, then `pathtrace`.
fn method_parser() -> impl clap::builder::TypedValueParser<Value = MethodArg> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser as _};
    let mut values: Vec<PossibleValue> = methods::REGISTRY
        .iter()
        .map(|d| PossibleValue::new(d.key().name()).help(d.help()))
        .collect();
    values.push(PossibleValue::new(crate::pathtrace::NAME).help(crate::pathtrace::HELP));
    PossibleValuesParser::new(values).map(|name| match methods::by_name(&name) {
        Ok(d) => MethodArg::Gpu(d.key()),
        Err(_) => MethodArg::PathTrace,
    })
}

#[derive(Args, Clone)]
pub struct RunArgs {
    /// The scene: glTF 2.0 (.gltf, .glb), Wavefront OBJ (.obj, with its MTL
    /// and textures) or a scene description naming either with lights,
    /// camera and motion (NAME.scene.json; README, "Scenes from the
    /// archives"); the built-in Cornell box when omitted.
    #[arg(long, help_heading = "Scene, lights and camera")]
    pub scene: Option<PathBuf>,
    /// Let the scene's files (buffers, images, an OBJ's MTL and textures, a
    /// description's mesh) be outside its folder (absolute paths, '..',
    /// file: URIs, symbolic links out of it).
    #[arg(
        long,
        help_heading = "Scene, lights and camera",
        hide_short_help = true
    )]
    pub allow_outside_uris: bool,
    /// A light instead of the scene's (repeat for several):
    /// `spot:position=X,Y,Z:target=X,Y,Z[:cone=DEG][:inner=DEG][:intensity=CD][:color=R,G,B][:range=M]`,
    /// `point:position=X,Y,Z[:intensity=CD]...` or
    /// `directional:direction=X,Y,Z[:intensity=LUX]...`, in metres with +Y
    /// up. Intensity defaults to what makes a white surface at the target
    /// (or the scene's centre) facing the light reflect radiance 1; the cone
    /// (outer half-angle) to 45 degrees, the inner to 3/4 of it. Move it with
    /// --orbit-light, or give it a path in a scene description.
    #[arg(long, value_name = "SPEC", value_parser = crate::scene::description::parse_light, help_heading = "Scene, lights and camera")]
    pub light: Vec<crate::scene::description::LightSpec>,
    /// The camera instead of the scene's:
    /// `position=X,Y,Z[:target=X,Y,Z][:fov=DEG][:znear=M]` (target default:
    /// the scene's centre; fov vertical, default 45; znear default 1/1000 of
    /// the scene's diagonal). Move it with --orbit-camera.
    #[arg(long, value_name = "SPEC", value_parser = crate::scene::description::parse_camera, help_heading = "Scene, lights and camera")]
    pub camera: Option<crate::scene::description::CameraSpec>,
    /// How indirect light is computed.
    #[arg(long, value_parser = method_parser(), default_value = D.method.name(), help_heading = "Method")]
    pub method: MethodArg,
    /// Output width in pixels.
    #[arg(long, default_value_t = D.width, help_heading = "Size")]
    pub width: u32,
    /// Output height in pixels.
    #[arg(long, default_value_t = D.height, help_heading = "Size")]
    pub height: u32,
    /// Reflective shadow map resolution R (R x R, a power of two).
    #[arg(long, default_value_t = D.rsm_resolution, help_heading = "Size")]
    pub rsm: u32,
    /// Shadow map resolution S of the direct light (S x S, a power of two;
    /// default: 8 texels per pixel of the longer image side, 1024 to 4096).
    #[arg(long, value_name = "N", help_heading = "Size", hide_short_help = true)]
    pub shadow: Option<u32>,
    /// Multiplier on radiance before the PNG's sRGB encoding.
    #[arg(long, default_value_t = D.exposure, help_heading = "Output")]
    pub exposure: f32,
    /// Animation time in seconds: the scene's glTF animations (and the
    /// --orbit-* motion) at this time. With --sequence, the first frame's time.
    #[arg(
        long,
        default_value_t = 0.0,
        allow_negative_numbers = true,
        help_heading = "Animation"
    )]
    pub time: f32,
    /// Load the Khronos validation layer with synchronization validation; exit
    /// non-zero if it reports anything.
    #[arg(long, help_heading = "Device", hide_short_help = true)]
    pub validate: bool,
    /// Device index from `isr devices` (default: discrete > integrated > virtual > CPU).
    #[arg(long, help_heading = "Device", hide_short_help = true)]
    pub device: Option<usize>,
    #[command(flatten)]
    pub params: ParamArgs,
}

impl RunArgs {
    /// The settings of a run of GPU method `method`, warning of parameters
    /// it does not read.
    pub fn settings(&self, method: Method) -> RenderSettings {
        let s = RenderSettings {
            width: self.width,
            height: self.height,
            rsm_resolution: self.rsm,
            shadow_resolution: self.shadow.unwrap_or(0),
            method,
            exposure: self.exposure,
            params: self.params.0.clone(),
            ..RenderSettings::default()
        };
        for name in methods::unused_params(&s) {
            eprintln!("warning: method {method} does not read --{name}; it has no effect");
        }
        s
    }

    /// The scene: `--scene`'s file (glTF, OBJ or a description, by its
    /// extension), or the built-in Cornell box; with `--light` and
    /// `--camera` in place of its own.
    pub fn load_scene(&self) -> Result<crate::scene::Scene> {
        let mut scene = match &self.scene {
            Some(path) => crate::scene::load_file(
                path,
                &crate::scene::LoadOptions {
                    allow_outside_uris: self.allow_outside_uris,
                    ..Default::default()
                },
            )?,
            None => crate::scene::cornell::cornell_box(),
        };
        // What the command line gives is not placed.
        scene.bare.light &= self.light.is_empty();
        scene.bare.camera &= self.camera.is_none();
        let placed = crate::placement::place_bare(&mut scene);
        if placed.is_some() {
            // The loader's warnings of its made-up light and camera no
            // longer hold: the line below says what replaced them.
            scene
                .warnings
                .retain(|w| !(w.contains("default spot light") || w.contains("default camera")));
        }
        if !self.light.is_empty() || self.camera.is_some() {
            let lights: Vec<(String, crate::scene::description::LightSpec)> = self
                .light
                .iter()
                .enumerate()
                .map(|(i, l)| (format!("--light {}", i + 1), l.clone()))
                .collect();
            crate::scene::description::apply(&mut scene, &lights, self.camera.as_ref())?;
            // What the file's warnings said of its default light or camera
            // no longer holds.
            scene.warnings.retain(|w| {
                !((!lights.is_empty() && w.contains("default spot light"))
                    || (self.camera.is_some() && w.contains("default camera")))
            });
        }
        let shrunk = crate::frame::texture_arrays::warnings(&scene.textures);
        scene.warnings.extend(shrunk);
        for w in &scene.warnings {
            eprintln!("warning: {w}");
        }
        if let Some(p) = placed {
            eprintln!("{}", p.line);
        }
        Ok(scene)
    }

    pub fn gpu_options(&self) -> GpuOptions {
        GpuOptions {
            validation: if self.validate {
                Validation::Required
            } else {
                Validation::Off
            },
            device_index: self.device,
        }
    }

    /// `--time` is a finite number.
    pub fn check_time(&self) -> Result<()> {
        if !self.time.is_finite() {
            bail!(
                "--time {}: the animation time must be a finite number of seconds",
                self.time
            );
        }
        Ok(())
    }
}
