//! `isr view`: the renderer's frames in a window. The frame is the same as
//! `isr render`'s (`Renderer::render_frame` records the same passes); the
//! viewer adds presentation (`present`): a swapchain image acquired, the
//! frame's image scaled into it, a text overlay with the per-pass GPU times,
//! then presented. Keys move the camera and the light, switch methods and
//! parameters (only the method's resources are made anew), and pick what is
//! shown (`controls`); `--script` plays timed input (`script`).

pub mod controls;
pub mod overlay;
pub mod present;
pub mod script;

use crate::gpu_types::{PRESENT_VIEW_FINAL, PRESENT_VIEW_HOST, PRESENT_VIEW_INDIRECT};
use crate::renderer::Renderer;
use crate::scene::Scene;
use crate::settings::{Method, Param, ParamType, RenderSettings};
use crate::vk::swapchain::{Semaphores, Surface, Swapchain};
use crate::vk::{Gpu, GpuOptions};
use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;
use controls::{Controls, Key};
use overlay::PassAverages;
use present::{PresentFrame, Presenter, COLUMNS, ROWS};
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

/// Seconds between overlay updates.
const OVERLAY_PERIOD: f64 = 0.25;

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

    /// A key press from the window (`scripted` false) or the script.
    fn press(&mut self, key: Key, scripted: bool) {
        let result = match key {
            Key::Method => {
                let i = self
                    .methods
                    .iter()
                    .position(|&m| m == self.renderer.settings.method)
                    .map_or(0, |i| (i + 1) % self.methods.len());
                let mut s = self.renderer.settings.clone();
                s.method = self.methods[i];
                self.switch(s, "method")
            }
            Key::TauDown | Key::TauUp => {
                let f = if key == Key::TauUp { 2.0 } else { 0.5 };
                self.scale(&crate::methods::hisr::TAU, f, "tau")
            }
            Key::VplsDown | Key::VplsUp => {
                let f = if key == Key::VplsUp { 4.0 } else { 0.25 };
                self.scale(&crate::methods::vpls::VPLS, f, "VPLs")
            }
            Key::View => {
                self.shown = self.shown.next();
                self.status = format!("view: {}", self.shown.name());
                Ok(())
            }
            Key::Pause => {
                self.paused = !self.paused;
                Ok(())
            }
            Key::Step => {
                self.paused = true;
                self.time += 1.0 / 30.0;
                Ok(())
            }
            Key::Reset => {
                self.controls.reset();
                Ok(())
            }
            Key::Screenshot => {
                self.screenshots_taken += 1;
                self.screenshot_to = Some(PathBuf::from(format!(
                    "isr-view-{}.png",
                    self.screenshots_taken
                )));
                Ok(())
            }
            Key::Quit => {
                self.quit = true;
                Ok(())
            }
            _ => {
                self.controls.press(key, scripted);
                Ok(())
            }
        };
        if let Err(e) = result {
            // A refused change keeps the current settings; the overlay says why.
            self.status = format!("{e:#}");
            eprintln!("isr view: {e:#}");
        }
    }

    /// Switches the method or its parameters: only the method's resources are made anew.
    /// Multiplies parameter `p` by `factor`, kept inside its range (a step
    /// toward an open bound goes halfway to it), and switches to it.
    fn scale<T: Scalable>(&mut self, p: &Param<T>, factor: f64, what: &str) -> Result<()> {
        let mut s = self.renderer.settings.clone();
        let old = p.get(&s);
        let new = p.clamp_from(old, T::from_f64(old.to_f64() * factor));
        p.set(&mut s, T::from_f64(new));
        self.switch(s, what)
    }

    fn switch(&mut self, settings: RenderSettings, what: &str) -> Result<()> {
        let started = Instant::now();
        self.renderer.set_method_settings(&settings)?;
        self.status = format!(
            "{what}: method resources made in {:.0} ms",
            started.elapsed().as_secs_f64() * 1e3
        );
        self.stats = PassAverages::default();
        Ok(())
    }

    /// Waits for the frames in flight, keeping their numbers for the overlay.
    fn wait_idle(&mut self) -> Result<()> {
        for samples in self.renderer.wait_idle()? {
            self.stats.add(&samples);
        }
        Ok(())
    }

    fn recreate_swapchain(&mut self) -> Result<()> {
        self.wait_idle()?;
        let size = self.window.inner_size();
        let old = self.swapchain.take();
        self.swapchain = Swapchain::new(
            self.gpu,
            &self.surface,
            (size.width, size.height),
            old.as_ref(),
        )?;
        drop(old);
        if let Some(sc) = &self.swapchain {
            if sc.format != self.presenter.format {
                bail!("the window's surface format changed ({:?})", sc.format);
            }
        }
        self.resized = false;
        Ok(())
    }

    /// Runs the script's commands that are due, up to and including the
    /// first screenshot (so that it shows what the commands before it did).
    fn run_script(&mut self) {
        let Some(start) = self.first_presented else {
            return;
        };
        let now = start.elapsed().as_secs_f64();
        while let Some(c) = self.script.get(self.next_command) {
            if c.seconds > now {
                break;
            }
            let command = c.command.clone();
            self.next_command += 1;
            match command {
                script::Command::Key(k) => self.press(k, true),
                script::Command::Screenshot(p) => {
                    // The shot shows this frame: later commands wait for the next one.
                    self.screenshot_to = Some(p);
                    break;
                }
                script::Command::Resize(w, h) => {
                    let _ = self
                        .window
                        .request_inner_size(winit::dpi::PhysicalSize::new(w, h));
                }
                script::Command::Quit => self.quit = true,
            }
        }
    }

    /// One frame: advance time and controls, render, present, and whatever
    /// the frame was asked for (a screenshot, a host-made debug view).
    fn frame(&mut self) -> Result<()> {
        let now = Instant::now();
        let dt = self
            .last_frame
            .map_or(0.0, |t| (now - t).as_secs_f32().min(0.25));
        self.last_frame = Some(now);
        if !self.paused {
            self.time += dt;
        }
        self.controls.advance(dt);
        self.run_script();
        if self.quit {
            return Ok(());
        }
        if self.resized || self.swapchain.is_none() {
            self.recreate_swapchain()?;
        }
        self.update_overlay();
        let Some(sc) = &self.swapchain else {
            // Minimised: nothing to draw into until the window has an area again.
            std::thread::sleep(std::time::Duration::from_millis(20));
            return Ok(());
        };

        if let Some(samples) = self.renderer.wait_next_slot()? {
            self.stats.add(&samples);
        }
        let acquire = self.acquire.list[self.renderer.next_slot_index()];
        let index = match unsafe {
            sc.loader
                .acquire_next_image(sc.swapchain, u64::MAX, acquire, vk::Fence::null())
        } {
            Ok((i, _suboptimal)) => i as usize,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.resized = true;
                return Ok(());
            }
            Err(e) => return Err(anyhow!("acquiring a swapchain image: {e}")),
        };

        // An animation that breaks a pose at some time ends the run with
        // the message that names it, as `isr render` does.
        let mut state = self.scene.pose_at(self.time)?;
        self.controls.apply(&mut state);
        self.renderer.update(&state)?;

        let host = matches!(self.shown, Shown::Levels | Shown::VplCount)
            && self.renderer.multires().is_some();
        let shown = match self.shown {
            Shown::Final => PRESENT_VIEW_FINAL,
            Shown::Indirect => PRESENT_VIEW_INDIRECT,
            _ if host => PRESENT_VIEW_HOST,
            _ => PRESENT_VIEW_FINAL,
        };
        let screenshot = self.screenshot_to.is_some();
        let mut frame = PresentFrame {
            gpu: self.gpu,
            presenter: &mut self.presenter,
            image: sc.images[index],
            view: sc.views[index],
            extent: sc.extent,
            acquired: acquire,
            rendered: sc.rendered[index],
            shown,
            cells: &self.cells,
            screenshot,
        };
        if let Some(samples) = self.renderer.render_frame(&mut frame)? {
            self.stats.add(&samples);
        }
        let waits = [sc.rendered[index]];
        let swapchains = [sc.swapchain];
        let indices = [index as u32];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        match unsafe { sc.loader.queue_present(self.gpu.queue, &info) } {
            Ok(false) => {}
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.resized = true,
            Err(e) => return Err(anyhow!("presenting: {e}")),
        }
        if self.first_presented.is_none() {
            self.first_presented = Some(Instant::now());
        }
        let (w, h) = (sc.extent.width, sc.extent.height);
        if screenshot {
            self.wait_idle()?;
            let path = self.screenshot_to.take().unwrap();
            let rgba = self
                .presenter
                .screenshot_rgba()
                .context("the screenshot's copy is missing")?;
            crate::output::write_png(&path, w, h, &rgba)?;
            eprintln!("isr view: wrote {} ({w}x{h})", path.display());
        }
        if host {
            // Levels and vpl-count are made on the host from the frame's
            // multiresolution buffer, as `isr render --debug-view` makes them,
            // and shown from the next frame on (slow: a readback per frame).
            self.wait_idle()?;
            if let Some(m) = self.renderer.readback_multires()? {
                let rgba = if self.shown == Shown::Levels {
                    crate::debug_view::levels_png(&m)
                } else {
                    crate::debug_view::vpl_count_png(&m).0
                };
                self.presenter.stage_host_view(&rgba);
            }
        }
        Ok(())
    }

    /// Rewrites the overlay's text a few times a second.
    fn update_overlay(&mut self) {
        let now = Instant::now();
        if self
            .overlay_updated
            .is_some_and(|t| (now - t).as_secs_f64() < OVERLAY_PERIOD)
        {
            return;
        }
        self.cells = overlay::cells(&overlay::Shown {
            settings: &self.renderer.settings,
            view: self.shown.name(),
            stats: &self.stats,
            time: self.time,
            paused: self.paused,
            status: &self.status,
        });
        self.stats = PassAverages {
            started: Some(now),
            ..Default::default()
        };
        self.overlay_updated = Some(now);
    }
}

/// A numeric parameter the viewer's keys scale.
trait Scalable: ParamType {
    fn to_f64(self) -> f64;
    fn from_f64(x: f64) -> Self;
}

impl Scalable for f32 {
    fn to_f64(self) -> f64 {
        self as f64
    }
    fn from_f64(x: f64) -> Self {
        x as f32
    }
}

impl Scalable for u32 {
    fn to_f64(self) -> f64 {
        self as f64
    }
    fn from_f64(x: f64) -> Self {
        x.round().clamp(0.0, u32::MAX as f64) as u32
    }
}
