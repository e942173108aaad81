//! One frame of the viewer: time and controls advanced, the script's due
//! commands run, the swapchain made anew when the window changed, the frame
//! rendered and presented, then what it was asked for (a screenshot, a
//! host-made debug view) and the overlay's text. Apart from the window's
//! events in `viewer`, which only ask for frames.

use super::overlay::{self, PassAverages};
use super::present::PresentFrame;
use super::{script, Shown, Viewer};
use crate::gpu_types::{PRESENT_VIEW_FINAL, PRESENT_VIEW_HOST, PRESENT_VIEW_INDIRECT};
use crate::vk::swapchain::Swapchain;
use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;
use std::time::Instant;

/// Seconds between overlay updates.
const OVERLAY_PERIOD: f64 = 0.25;

impl Viewer<'_> {
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
    pub(super) fn frame(&mut self) -> Result<()> {
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
