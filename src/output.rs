//! Writing results: a multi-layer OpenEXR of linear data and a PNG for viewing.

use crate::readback::Readback;
use anyhow::{anyhow, Context as _, Result};
use exr::prelude::*;
use std::path::Path;

fn ensure_parent(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| {
            format!(
                "cannot create directory {} for {}",
                dir.display(),
                path.display()
            )
        })?;
    }
    Ok(())
}

fn rgb_layer(name: &str, w: usize, h: usize, data: &[[f32; 4]]) -> Layer<AnyChannels<FlatSamples>> {
    let channel = |c: &str, k: usize| {
        AnyChannel::new(c, FlatSamples::F32(data.iter().map(|p| p[k]).collect()))
    };
    Layer::new(
        (w, h),
        LayerAttributes::named(name),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(vec![
            channel("R", 0),
            channel("G", 1),
            channel("B", 2),
        ])),
    )
}

/// Layers `final`, `direct`, `indirect` (radiance W/(m^2 sr); `indirect` is
/// the irradiance E in W/m^2 before the albedo/pi of the composite), `albedo`,
/// `normal` (world, unit) and `depth` (view depth in m; infinity on background).
pub fn write_exr(path: &Path, r: &Readback) -> Result<()> {
    ensure_parent(path)?;
    let (w, h) = (r.width as usize, r.height as usize);
    let depth: Vec<f32> = r
        .position
        .iter()
        .map(|p| if p[3] > 0.0 { p[3] } else { f32::INFINITY })
        .collect();
    let layers = vec![
        rgb_layer("final", w, h, &r.final_radiance),
        rgb_layer("direct", w, h, &r.direct),
        rgb_layer("indirect", w, h, &r.indirect),
        rgb_layer("albedo", w, h, &r.albedo),
        rgb_layer("normal", w, h, &r.normal),
        Layer::new(
            (w, h),
            LayerAttributes::named("depth"),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
                "Z",
                FlatSamples::F32(depth),
            )])),
        ),
    ];
    let image = Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((w, h))),
        layers,
    );
    image
        .write()
        .to_file(path)
        .map_err(|e| anyhow!("cannot write {}: {e}", path.display()))
}

/// The tonemapped image (exposure, clamp, sRGB) as an 8-bit RGB PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<()> {
    ensure_parent(path)?;
    let rgb: Vec<u8> = rgba8
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    image::save_buffer(path, &rgb, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| anyhow!("cannot write {}: {e}", path.display()))
}
