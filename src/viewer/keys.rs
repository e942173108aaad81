//! What the viewer's keys do beyond moving the camera and the light
//! (`controls`): switch the method, scale its parameters (only the
//! method's resources are made anew), cycle the debug view, pause, step,
//! take a screenshot, quit. Apart from the window's events in `viewer`
//! because a script's key presses come here too.

use super::controls::Key;
use super::overlay::PassAverages;
use super::Viewer;
use crate::settings::RenderSettings;
use anyhow::{bail, Result};
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
            Key::KnobDown | Key::KnobUp => self.scale_knob(key == Key::KnobUp),
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

    /// Multiplies the method's main knob (`Descriptor::main_param`) by its
    /// step, 2 or the power its values take (4 for the VPL count), or
    /// divides it, kept inside its range, and switches to it.
    fn scale_knob(&mut self, up: bool) -> Result<()> {
        let mut s = self.renderer.settings.clone();
        let d = crate::methods::find(s.method)?;
        let Some(p) = d.main_param() else {
            bail!("method {} has no main knob to scale", s.method);
        };
        let step = p.range().power_of.unwrap_or(2) as f64;
        let factor = if up { step } else { 1.0 / step };
        let Some(v) = p.scaled_in(&s, factor) else {
            bail!("--{} is not a number the keys can scale", p.name());
        };
        s.params.insert(p.name(), v);
        self.switch(s, p.name())
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
