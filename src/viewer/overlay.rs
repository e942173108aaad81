//! The overlay's text: what is shown (method, parameters, fps, per-pass GPU
//! times averaged since the last update) laid out in the text grid the
//! `overlay` pass draws, one cell a character, `char | colour << 8`.

use super::present::{COLUMNS, ROWS};
use crate::settings::RenderSettings;
use crate::vk::profiler::PassSample;
use std::time::Instant;

/// Per-pass numbers averaged over the frames since the overlay's last update.
#[derive(Default)]
pub struct PassAverages {
    pub frames: u32,
    pub passes: Vec<(&'static str, bool, f64, u32)>,
    pub started: Option<Instant>,
}

impl PassAverages {
    pub fn add(&mut self, samples: &[PassSample]) {
        self.frames += 1;
        for s in samples {
            let Some(ms) = s.gpu_ms else { continue };
            match self.passes.iter_mut().find(|p| p.0 == s.name) {
                Some(p) => {
                    p.2 += ms;
                    p.3 += 1;
                }
                None => self.passes.push((s.name, s.kind.indirect, ms, 1)),
            }
        }
    }
}

/// What the overlay reports.
pub struct Shown<'a> {
    pub settings: &'a RenderSettings,
    pub view: &'a str,
    pub stats: &'a PassAverages,
    pub time: f32,
    pub paused: bool,
    pub status: &'a str,
}

/// The overlay's cells for `s` (colours: 0 white, 1 yellow, 2 grey, 3 cyan
/// for the indirect passes).
pub fn cells(s: &Shown) -> Vec<u32> {
    let elapsed = s.stats.started.map_or(0.0, |t| t.elapsed().as_secs_f64());
    let fps = if elapsed > 0.0 {
        s.stats.frames as f64 / elapsed
    } else {
        0.0
    };
    let settings = s.settings;
    let mut lines: Vec<(u32, String)> = vec![
        (
            1,
            format!(
                "isr view  {}  {}x{}  rsm {}",
                settings.method.name(),
                settings.width,
                settings.height,
                settings.rsm_resolution
            ),
        ),
        (
            0,
            format!(
                "{}  view {}",
                crate::methods::find(settings.method)
                    .map(|d| d.label(settings))
                    .unwrap_or_default(),
                s.view
            ),
        ),
    ];
    let mut total = 0.0;
    let mut indirect = 0.0;
    let mut pass_lines = Vec::new();
    for &(name, is_indirect, sum, n) in &s.stats.passes {
        let ms = sum / n.max(1) as f64;
        total += ms;
        if is_indirect {
            indirect += ms;
        }
        pass_lines.push((
            if is_indirect { 3 } else { 0 },
            format!("{name:<22}{ms:>9.2} ms"),
        ));
    }
    lines.push((
        1,
        format!("fps {fps:.1}  gpu {total:.1} ms  indirect {indirect:.1} ms"),
    ));
    lines.extend(pass_lines);
    lines.push((
        2,
        format!(
            "t {:.2} s{}",
            s.time,
            if s.paused { " (paused)" } else { "" }
        ),
    ));
    lines.push((2, s.status.to_string()));
    lines.push((2, "M method  [ ] tau  , . vpls  V view  P pause".into()));
    let mut cells = vec![0u32; COLUMNS * ROWS];
    for (row, (colour, text)) in lines.iter().take(ROWS).enumerate() {
        for (col, ch) in text.chars().take(COLUMNS).enumerate() {
            let c = if ch.is_ascii() { ch as u32 } else { '?' as u32 };
            cells[row * COLUMNS + col] = c | colour << 8;
        }
    }
    cells
}
