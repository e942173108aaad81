//! The image files `isr` writes: the multi-layer OpenEXR of linear data,
//! the tonemapped PNG and the animated GIF. Apart from the checks and the
//! atomic write in `output`, which they go through, because they are the
//! formats' encoders and nothing else.

use super::write_atomic;
use crate::readback::Readback;
use anyhow::{anyhow, Result};
use exr::prelude::*;
use std::path::Path;

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
/// `normal` (world, unit) and `depth` (view depth in m; infinity on background);
/// and where the run kept them (the path tracer), the layers of `indirect`
/// by bounce (`bounces::LAYERS`: `indirect.bounce1` ...), irradiance as it.
pub fn write_exr(path: &Path, r: &Readback) -> Result<()> {
    let (w, h) = (r.width as usize, r.height as usize);
    let depth: Vec<f32> = r
        .position
        .iter()
        .map(|p| if p[3] > 0.0 { p[3] } else { f32::INFINITY })
        .collect();
    let mut layers = vec![
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
    // The light of each bounce, where the renderer kept it apart, so that
    // any smaller number of bounces is read from one run.
    for (name, layer) in crate::bounces::LAYERS.iter().zip(&r.bounces) {
        layers.push(rgb_layer(name, w, h, layer));
    }
    let image = Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((w, h))),
        layers,
    );
    write_atomic(path, |out| {
        image.write().to_buffered(out).map_err(|e| anyhow!("{e}"))
    })
}

/// The tonemapped image (exposure, clamp, sRGB) as an 8-bit RGB PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<()> {
    let rgb: Vec<u8> = rgba8
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    write_atomic(path, |out| {
        image::write_buffer_with_format(
            out,
            &rgb,
            width,
            height,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(|e| anyhow!("{e}"))
    })
}

/// Tonemapped RGBA8 frames as a looping animated GIF at `fps` (each frame
/// quantised to its own 256-colour palette by the encoder).
pub fn write_gif(
    path: &Path,
    width: u32,
    height: u32,
    frames: Vec<Vec<u8>>,
    fps: f32,
) -> Result<()> {
    use image::codecs::gif::{GifEncoder, Repeat};
    // GIF delays are whole hundredths of a second.
    let delay = image::Delay::from_numer_denom_ms((1000.0 / fps).round().max(10.0) as u32, 1);
    write_atomic(path, |out| {
        let mut encoder = GifEncoder::new_with_speed(out, 10);
        encoder.set_repeat(Repeat::Infinite)?;
        for rgba in frames {
            let image = image::RgbaImage::from_raw(width, height, rgba)
                .ok_or_else(|| anyhow!("a frame does not have {width}x{height} pixels"))?;
            encoder.encode_frame(image::Frame::from_parts(image, 0, 0, delay))?;
        }
        Ok(())
    })
}
