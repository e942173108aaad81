//! The viewer's keys (one table: the window's key codes, the script's names,
//! the README's list) and the camera and light they move.

use crate::scene::{Camera, FrameState};
use anyhow::{bail, Result};
use glam::{Quat, Vec3};
use winit::keyboard::KeyCode;

/// What a key does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Key {
    Forward,
    Back,
    Left,
    Right,
    Up,
    Down,
    LightLeft,
    LightRight,
    LightAway,
    LightToward,
    LightUp,
    LightDown,
    AimLeft,
    AimRight,
    AimUp,
    AimDown,
    Method,
    KnobDown,
    KnobUp,
    View,
    Pause,
    Step,
    Reset,
    Screenshot,
    Quit,
}

/// Every key: its code, the name scripts use, and what it does (README).
pub const KEYS: &[(Key, KeyCode, &str, &str)] = &[
    (Key::Forward, KeyCode::KeyW, "W", "camera forward (held)"),
    (Key::Back, KeyCode::KeyS, "S", "camera back (held)"),
    (Key::Left, KeyCode::KeyA, "A", "camera left (held)"),
    (Key::Right, KeyCode::KeyD, "D", "camera right (held)"),
    (Key::Up, KeyCode::KeyE, "E", "camera up (held)"),
    (Key::Down, KeyCode::KeyQ, "Q", "camera down (held)"),
    (Key::LightLeft, KeyCode::ArrowLeft, "Left", "light -x"),
    (Key::LightRight, KeyCode::ArrowRight, "Right", "light +x"),
    (Key::LightAway, KeyCode::ArrowUp, "Up", "light -z"),
    (Key::LightToward, KeyCode::ArrowDown, "Down", "light +z"),
    (Key::LightUp, KeyCode::PageUp, "PageUp", "light up"),
    (Key::LightDown, KeyCode::PageDown, "PageDown", "light down"),
    (Key::AimLeft, KeyCode::KeyJ, "J", "aim the light left"),
    (Key::AimRight, KeyCode::KeyL, "L", "aim the light right"),
    (Key::AimUp, KeyCode::KeyI, "I", "aim the light up"),
    (Key::AimDown, KeyCode::KeyK, "K", "aim the light down"),
    (Key::Method, KeyCode::KeyM, "M", "next method"),
    (
        Key::KnobDown,
        KeyCode::BracketLeft,
        "[",
        "the method's main knob (HISR's tau, the VPL count) / 2 (/ 4 for a power of 4)",
    ),
    (
        Key::KnobUp,
        KeyCode::BracketRight,
        "]",
        "the method's main knob x 2 (x 4 for a power of 4)",
    ),
    (
        Key::View,
        KeyCode::KeyV,
        "V",
        "next view: final, indirect, levels, vpl-count",
    ),
    (Key::Pause, KeyCode::KeyP, "P", "pause / play the animation"),
    (
        Key::Step,
        KeyCode::KeyN,
        "N",
        "step the animation by 1/30 s (pauses)",
    ),
    (Key::Reset, KeyCode::KeyR, "R", "reset camera and light"),
    (
        Key::Screenshot,
        KeyCode::F12,
        "F12",
        "screenshot to isr-view-N.png",
    ),
    (Key::Quit, KeyCode::Escape, "Escape", "quit"),
];

impl Key {
    pub fn from_code(code: KeyCode) -> Option<Key> {
        KEYS.iter().find(|k| k.1 == code).map(|k| k.0)
    }

    /// A script's key name (letters in either case).
    pub fn from_name(name: &str) -> Result<Key> {
        if let Some(k) = KEYS.iter().find(|k| k.2.eq_ignore_ascii_case(name)) {
            return Ok(k.0);
        }
        let names: Vec<&str> = KEYS.iter().map(|k| k.2).collect();
        bail!("unknown key `{name}`; keys: {}", names.join(" "))
    }

    /// Camera movement keys act while held.
    pub fn is_held_motion(self) -> bool {
        matches!(
            self,
            Key::Forward | Key::Back | Key::Left | Key::Right | Key::Up | Key::Down
        )
    }
}

/// The camera the user flies and the offset they gave the light.
pub struct Controls {
    initial: (Vec3, f32, f32),
    pub position: Vec3,
    /// Radians about +Y (0: looking along -Z) and above the horizon.
    pub yaw: f32,
    pub pitch: f32,
    yfov: f32,
    znear: f32,
    /// Metres per second of camera motion, and per light-move key press.
    speed: f32,
    pub light_offset: Vec3,
    pub light_yaw: f32,
    pub light_pitch: f32,
    held: Vec<Key>,
    /// Scripted presses of motion keys: seconds of motion still to apply.
    pulses: Vec<(Key, f32)>,
}

/// A key press turns the light's aim by this much.
const AIM_STEP: f32 = 5.0 * std::f32::consts::PI / 180.0;
/// Mouse-look radians per pixel of drag.
const LOOK_PER_PIXEL: f32 = 0.004;
/// Seconds of motion one scripted press of a held key stands for.
const PULSE_SECONDS: f32 = 0.25;

impl Controls {
    /// Starts at `camera`; `extent` (the scene's size, m) sets the speeds.
    pub fn new(camera: &Camera, extent: f32) -> Self {
        let f = camera.forward();
        let (yaw, pitch) = (f.x.atan2(-f.z), f.y.clamp(-1.0, 1.0).asin());
        Self {
            initial: (camera.position(), yaw, pitch),
            position: camera.position(),
            yaw,
            pitch,
            yfov: camera.yfov,
            znear: camera.znear,
            speed: 0.25 * extent.max(1e-3),
            light_offset: Vec3::ZERO,
            light_yaw: 0.0,
            light_pitch: 0.0,
            held: Vec::new(),
            pulses: Vec::new(),
        }
    }

    pub fn forward(&self) -> Vec3 {
        Vec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            -self.pitch.cos() * self.yaw.cos(),
        )
    }

    pub fn camera(&self) -> Camera {
        Camera::look_at(
            self.position,
            self.position + self.forward(),
            Vec3::Y,
            self.yfov,
            self.znear,
        )
    }

    pub fn reset(&mut self) {
        (self.position, self.yaw, self.pitch) = self.initial;
        self.light_offset = Vec3::ZERO;
        self.light_yaw = 0.0;
        self.light_pitch = 0.0;
    }

    /// A key went down (`scripted`: a press without a release).
    pub fn press(&mut self, key: Key, scripted: bool) {
        let step = self.speed * 0.4;
        match key {
            k if k.is_held_motion() => {
                if scripted {
                    self.pulses.push((k, PULSE_SECONDS));
                } else if !self.held.contains(&k) {
                    self.held.push(k);
                }
            }
            Key::LightLeft => self.light_offset.x -= step,
            Key::LightRight => self.light_offset.x += step,
            Key::LightAway => self.light_offset.z -= step,
            Key::LightToward => self.light_offset.z += step,
            Key::LightUp => self.light_offset.y += step,
            Key::LightDown => self.light_offset.y -= step,
            Key::AimLeft => self.light_yaw += AIM_STEP,
            Key::AimRight => self.light_yaw -= AIM_STEP,
            Key::AimUp => self.light_pitch = (self.light_pitch + AIM_STEP).min(1.5),
            Key::AimDown => self.light_pitch = (self.light_pitch - AIM_STEP).max(-1.5),
            _ => {}
        }
    }

    pub fn release(&mut self, key: Key) {
        self.held.retain(|&k| k != key);
    }

    /// Forgets held keys (the window lost focus: releases would not arrive).
    pub fn release_all(&mut self) {
        self.held.clear();
    }

    /// Mouse-look by a drag of `dx, dy` pixels.
    pub fn look(&mut self, dx: f64, dy: f64) {
        self.yaw += dx as f32 * LOOK_PER_PIXEL;
        self.pitch = (self.pitch - dy as f32 * LOOK_PER_PIXEL).clamp(-1.55, 1.55);
    }

    /// Moves the camera for `dt` seconds of held keys and scripted pulses.
    pub fn advance(&mut self, dt: f32) {
        let f = self.forward();
        let right = f.cross(Vec3::Y).normalize_or_zero();
        let dir = |k: Key| match k {
            Key::Forward => f,
            Key::Back => -f,
            Key::Left => -right,
            Key::Right => right,
            Key::Up => Vec3::Y,
            Key::Down => -Vec3::Y,
            _ => Vec3::ZERO,
        };
        let mut motion: Vec3 = self.held.iter().map(|&k| dir(k) * dt).sum();
        for (k, left) in &mut self.pulses {
            let t = dt.min(*left);
            motion += dir(*k) * t;
            *left -= t;
        }
        self.pulses.retain(|p| p.1 > 0.0);
        self.position += motion * self.speed;
    }

    /// `state` (the scene at the animation time) with the user's camera and
    /// the scene's first light moved and turned by the user's offsets.
    pub fn apply(&self, state: &mut FrameState) {
        state.camera = self.camera();
        let Some(l) = state.lights.first_mut() else {
            return;
        };
        l.position += self.light_offset;
        let right = l.direction.cross(Vec3::Y).normalize_or(Vec3::X);
        let turn =
            Quat::from_rotation_y(self.light_yaw) * Quat::from_axis_angle(right, self.light_pitch);
        l.direction = (turn * l.direction).normalize();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_names_and_codes_are_unique() {
        for (i, a) in KEYS.iter().enumerate() {
            for b in &KEYS[i + 1..] {
                assert!(
                    a.0 != b.0 && a.1 != b.1 && !a.2.eq_ignore_ascii_case(b.2),
                    "{a:?} {b:?}"
                );
            }
        }
        assert_eq!(Key::from_name("m").unwrap(), Key::Method);
        assert_eq!(Key::from_code(KeyCode::Escape), Some(Key::Quit));
    }

    /// The README's key table names every key (scripts use the same names).
    #[test]
    fn readme_lists_every_key() {
        let readme = include_str!("../../README.md");
        let table = readme
            .split("## Interactive")
            .nth(1)
            .and_then(|s| s.split("\n## ").next())
            .expect("README has an Interactive section");
        for (_, _, name, _) in KEYS {
            assert!(
                table.contains(&format!("`{name}`")),
                "README does not list `{name}`"
            );
        }
    }

    #[test]
    fn camera_round_trips_and_moves() {
        let cam = Camera::look_at(
            Vec3::new(0.0, 1.0, 3.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::Y,
            0.8,
            0.1,
        );
        let mut c = Controls::new(&cam, 2.0);
        assert!((c.camera().forward() - cam.forward()).length() < 1e-5);
        c.press(Key::Forward, true);
        for _ in 0..10 {
            c.advance(0.05);
        }
        // A scripted press is PULSE_SECONDS of motion at the scene's speed.
        assert!(
            (c.position.z - (3.0 - 0.25 * 0.5)).abs() < 1e-4,
            "{}",
            c.position
        );
    }
}
