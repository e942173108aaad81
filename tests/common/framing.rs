//! How much of a rendered image shows geometry and how much of that is
//! lit: what a new user sees of a bare scene (`placement`).

use super::cli::{Isr, Ran};
use std::path::Path;

/// What one bare render showed.
#[derive(Debug)]
pub struct Seen {
    pub pixels: usize,
    /// Pixels whose depth is finite: the camera sees a surface there.
    pub geometry: usize,
    /// Of those, pixels above 24/255 in some channel of the PNG.
    pub lit: usize,
    pub stderr: String,
}

impl Seen {
    /// Geometry covers at least a quarter of the image and at least half of
    /// it is lit (a bare archive scene was 0% to 8% lit before placement).
    pub fn framed_and_lit(&self) -> bool {
        self.geometry * 4 >= self.pixels && self.lit * 2 >= self.geometry
    }
}

/// Renders `scene` bare (no `--light`, no `--camera`) at `size` pixels
/// square with `extra` arguments, one frame, and measures it.
pub fn render_bare(dir: &Path, name: &str, scene: &Path, size: u32, extra: &[&str]) -> Seen {
    let png = dir.join(format!("{name}.png"));
    let exr = dir.join(format!("{name}.exr"));
    let s = size.to_string();
    let ran: Ran = Isr::render(dir)
        .args([
            "--frames", "1", "--width", &s, "--height", &s, "--rsm", "64",
        ])
        .args(extra)
        .arg("--scene")
        .arg(scene)
        .arg("--png")
        .arg(&png)
        .arg("--out")
        .arg(&exr)
        .succeeds();
    let image = exr::prelude::read_all_flat_layers_from_file(&exr).unwrap();
    let depth = image
        .layer_data
        .iter()
        .find(|l| {
            l.attributes
                .layer_name
                .as_ref()
                .map(|n| n.to_string())
                .as_deref()
                == Some("depth")
        })
        .expect("a depth layer");
    let depth: Vec<f32> = match &depth.channel_data.list[0].sample_data {
        exr::prelude::FlatSamples::F32(v) => v.clone(),
        other => panic!("depth: {other:?}"),
    };
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.pixels().len(), depth.len());
    let geometry: Vec<bool> = depth.iter().map(|d| d.is_finite() && *d > 0.0).collect();
    let lit = img
        .pixels()
        .zip(&geometry)
        .filter(|(p, &g)| g && p.0.iter().any(|&c| c > 24))
        .count();
    Seen {
        pixels: depth.len(),
        geometry: geometry.iter().filter(|&&g| g).count(),
        lit,
        stderr: ran.stderr,
    }
}
