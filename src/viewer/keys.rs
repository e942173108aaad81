//! What the viewer's keys do beyond moving the camera and the light
//! (`controls`): switch the method, scale its parameters (only the
//! method's resources are made anew), cycle the debug view, pause, step,
//! take a screenshot, quit. Apart from the window's events in `viewer`
//! because a script's key presses come here too.

use super::controls::Key;
use super::overlay::PassAverages;
use super::Viewer;
use crate::settings::{Param, ParamType, RenderSettings};
use anyhow::Result;
use std::path::PathBuf;
use std::time::Instant;

impl Viewer<'_> {
    /// A key press from the window (`scripted` false) or the script.
    pub(super) fn press(&mut self, key: Key, scripted: bool) {
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
                self.scale(&crate::regular_vpls::VPLS, f, "VPLs")
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

    /// Multiplies parameter `p` by `factor`, kept inside its range (a step
    /// toward an open bound goes halfway to it), and switches to it.
    fn scale<T: Scalable>(&mut self, p: &Param<T>, factor: f64, what: &str) -> Result<()> {
        let mut s = self.renderer.settings.clone();
        let old = p.get(&s);
        let new = p.clamp_from(old, T::from_f64(old.to_f64() * factor));
        p.set(&mut s, T::from_f64(new));
        self.switch(s, what)
    }

    /// Switches the method or its parameters: only the method's resources
    /// are made anew.
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
