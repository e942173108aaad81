//! `isr view`: the renderer's frames in a window. The frame is the same as
//! `isr render`'s (`Renderer::render_frame` records the same passes); the
//! viewer adds presentation (`present`): a swapchain image acquired, the
//! frame's image scaled into it, a text overlay with the per-pass GPU times,
//! then presented. Keys move the camera and the light, switch methods and
//! parameters (only the method's resources are made anew), and pick what is
//! shown (`controls`, and `keys` for what the viewer's own keys do);
//! `--script` plays timed input (`script`). This module holds the window,
//! its events and the viewer's state; `frame` draws one frame.

pub mod controls;
mod frame;
mod keys;
pub mod overlay;
pub mod present;
pub mod script;

use crate::renderer::Renderer;
use crate::scene::Scene;
use crate::settings::{Method, RenderSettings};
use crate::vk::swapchain::{Semaphores, Surface, Swapchain};
use crate::vk::{Gpu, GpuOptions};
use anyhow::{anyhow, bail, Context as _, Result};
use controls::{Controls, Key};
use overlay::PassAverages;
use present::{Presenter, COLUMNS, ROWS};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::PhysicalKey;
use winit::window::{Window, WindowId};

/// What `isr view` was asked for.
pub struct ViewOptions {
    pub settings: RenderSettings,
    pub gpu: GpuOptions,
    pub script: Vec<script::Timed>,
    /// Animation time at the start (seconds).
    pub time: f32,
    pub paused: bool,
}

/// Methods `M` cycles through: every GPU method that renders a frame in one
/// submission (`methods::Descriptor::interactive`: not `reference`, which
/// takes seconds per frame in chunks; `pathtrace` runs on the CPU).
pub fn interactive_methods() -> Vec<Method> {
    crate::methods::REGISTRY
        .iter()
        .filter(|d| d.interactive())
        .map(|d| d.key())
        .collect()
}

/// Help for a machine without a window system.
const NO_DISPLAY_HINT: &str = "isr view needs an X11 (DISPLAY) or Wayland \
     (WAYLAND_DISPLAY) session, or a virtual one such as `xvfb-run -a isr view` \
     (`sudo apt-get install xvfb`); `isr render` works headless";

/// The error of a window system that cannot be reached (`doing`: what
/// failed), saying what is wrong and what to do: winit's reason without the
/// source location its `OsError` carries ("os error at FILE:LINE: REASON",
/// a path in cargo's registry), the display variables as they are set, and
/// [`NO_DISPLAY_HINT`].
fn no_window_system(doing: &str, e: impl std::fmt::Display) -> anyhow::Error {
    let text = e.to_string();
    let reason = text
        .strip_prefix("os error at ")
        .and_then(|rest| rest.split_once(": "))
        .map_or(text.as_str(), |(_, reason)| reason)
        .trim_end_matches('.');
    let set: Vec<String> = ["DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"]
        .iter()
        .filter_map(|name| {
            let value = std::env::var_os(name).filter(|v| !v.is_empty())?;
            Some(format!("{name} {}", value.to_string_lossy()))
        })
        .collect();
    let set = if set.is_empty() {
        String::new()
    } else {
        format!(" ({})", set.join(", "))
    };
    anyhow!("{doing}: {reason}{set}. {NO_DISPLAY_HINT}")
}

/// The debug views `V` cycles through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Shown {
    Final,
    Indirect,
    Levels,
    VplCount,
}

impl Shown {
    fn name(self) -> &'static str {
        match self {
            Shown::Final => "final",
            Shown::Indirect => "indirect",
            Shown::Levels => "levels",
            Shown::VplCount => "vpl-count",
        }
    }
    fn next(self) -> Self {
        match self {
            Shown::Final => Shown::Indirect,
            Shown::Indirect => Shown::Levels,
            Shown::Levels => Shown::VplCount,
            Shown::VplCount => Shown::Final,
        }
    }
}

/// Runs the viewer until the window closes, `Escape` or a script's `quit`.
/// Fails when the validation layer (with `--validate`) reported anything.
pub fn run(scene: &Scene, options: ViewOptions) -> Result<()> {
    let connect = "isr view cannot connect to a window system";
    let event_loop = EventLoop::new().map_err(|e| no_window_system(connect, e))?;
    let display = event_loop
        .display_handle()
        .map_err(|e| no_window_system(connect, e))?
        .as_raw();
    let surface_extensions = ash_window::enumerate_required_extensions(display)
        .context("this window system has no Vulkan surface support")?;
    let gpu = Gpu::with_extensions(
        &options.gpu,
        surface_extensions,
        &[ash::khr::swapchain::NAME.as_ptr()],
    )
    .context("creating a Vulkan device that can show windows (surface and swapchain extensions)")?;
    eprintln!(
        "isr view: {} ({} triangles) at {}x{}, method {} on {}",
        scene.name,
        scene.triangle_count(),
        options.settings.width,
        options.settings.height,
        options.settings.method.name(),
        gpu.info.name
    );
    let mut app = App {
        gpu: &gpu,
        scene,
        options: &options,
        viewer: None,
        error: None,
    };
    event_loop.set_control_flow(ControlFlow::Poll);
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    let App { viewer, error, .. } = app;
    drop(viewer);
    if let Some(e) = error {
        return Err(e);
    }
    gpu.validation_verdict()
}

struct App<'g> {
    gpu: &'g Gpu,
    scene: &'g Scene,
    options: &'g ViewOptions,
    viewer: Option<Viewer<'g>>,
    error: Option<anyhow::Error>,
}

impl App<'_> {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        event_loop.exit();
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.viewer.is_some() {
            return;
        }
        match Viewer::new(self.gpu, self.scene, self.options, event_loop) {
            Ok(v) => self.viewer = Some(v),
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(v) = self.viewer.as_mut() else {
            return;
        };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => v.resized = true,
            WindowEvent::Focused(false) => v.controls.release_all(),
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return;
                };
                let Some(key) = Key::from_code(code) else {
                    return;
                };
                match event.state {
                    ElementState::Pressed => v.press(key, false),
                    ElementState::Released => v.controls.release(key),
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                v.dragging = state == ElementState::Pressed;
            }
            WindowEvent::CursorMoved { position, .. } => {
                let p = (position.x, position.y);
                if let (true, Some(last)) = (v.dragging, v.cursor) {
                    v.controls.look(p.0 - last.0, p.1 - last.1);
                }
                v.cursor = Some(p);
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = v.frame() {
                    self.fail(event_loop, e);
                    return;
                }
                if v.quit {
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(v) = &self.viewer {
            v.window.request_redraw();
        }
    }
}

struct Viewer<'g> {
    // Dropped in this order: swapchain, what frames use, renderer, surface, window.
    swapchain: Option<Swapchain>,
    presenter: Presenter,
    acquire: Semaphores,
    renderer: Renderer<'g>,
    surface: Surface,
    window: Arc<Window>,
    gpu: &'g Gpu,
    scene: &'g Scene,
    controls: Controls,
    methods: Vec<Method>,
    shown: Shown,
    resized: bool,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    quit: bool,
    // Animation.
    time: f32,
    paused: bool,
    last_frame: Option<Instant>,
    // Script, from the first presented frame.
    script: Vec<script::Timed>,
    next_command: usize,
    first_presented: Option<Instant>,
    screenshot_to: Option<PathBuf>,
    screenshots_taken: u32,
    // Overlay.
    stats: PassAverages,
    cells: Vec<u32>,
    status: String,
    overlay_updated: Option<Instant>,
}

impl<'g> Viewer<'g> {
    fn new(
        gpu: &'g Gpu,
        scene: &'g Scene,
        options: &ViewOptions,
        event_loop: &ActiveEventLoop,
    ) -> Result<Self> {
        let s = &options.settings;
        let attributes = Window::default_attributes()
            .with_title(format!("isr view: {}", scene.name))
            .with_inner_size(winit::dpi::PhysicalSize::new(s.width, s.height));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| no_window_system("isr view cannot create its window", e))?,
        );
        let surface = Surface::new(
            gpu,
            window.display_handle()?.as_raw(),
            window.window_handle()?.as_raw(),
        )?;
        let renderer = Renderer::new(gpu, scene, s)?;
        let size = window.inner_size();
        let swapchain = Swapchain::new(gpu, &surface, (size.width, size.height), None)?;
        let format = match &swapchain {
            Some(sc) => sc.format,
            None => bail!("the window has no area to draw into"),
        };
        let presenter =
            Presenter::new(gpu, renderer.frame_set_layout(), &renderer.targets, format)?;
        let acquire = Semaphores::new(gpu, crate::renderer::FRAMES_IN_FLIGHT)?;
        let extent = scene.bounds().map_or(1.0, |(lo, hi)| (hi - lo).length());
        let controls = Controls::new(&scene.state_at(options.time).camera, extent);
        Ok(Self {
            swapchain,
            presenter,
            acquire,
            renderer,
            surface,
            window,
            gpu,
            scene,
            controls,
            methods: interactive_methods(),
            shown: Shown::Final,
            resized: false,
            dragging: false,
            cursor: None,
            quit: false,
            time: options.time,
            paused: options.paused,
            last_frame: None,
            script: options.script.clone(),
            next_command: 0,
            first_presented: None,
            screenshot_to: None,
            screenshots_taken: 0,
            stats: PassAverages::default(),
            cells: vec![0; COLUMNS * ROWS],
            status: String::new(),
            overlay_updated: None,
        })
    }
}
