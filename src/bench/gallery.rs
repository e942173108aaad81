//! `gallery.png`, every method's image beside the reference's and its FLIP
//! heat map, and the heat map itself (written with each bench image).

use super::files;
use super::rows::Row;
use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::Path;

/// Black, red, yellow, white as FLIP rises from 0 to 1 (RGBA8).
pub fn heat_map(values: &[f32]) -> Vec<u8> {
    values
        .iter()
        .flat_map(|&v| {
            let v = v.clamp(0.0, 1.0) * 3.0;
            let c = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
            [c(v), c(v - 1.0), c(v - 2.0), 255]
        })
        .collect()
}

/// `gallery.png`: per scene and visibility (`visibilities`: each's label and
/// its images' suffix, `Plan::image_suffix`) two rows, every method's image
/// at its default (the middle animation frame) and its FLIP heat map against
/// the reference of that visibility, with the reference first; labelled
/// with method and error. A method that reads no visibility has blank cells
/// in the rows with visibility, and says so.
pub fn gallery(
    dir: &Path,
    rows: &[Row],
    scenes: &[String],
    methods: &[&str],
    visibilities: &[(String, &str)],
) -> Result<()> {
    let load = |p: &Path| -> Option<image::RgbaImage> { Some(image::open(p).ok()?.to_rgba8()) };
    let mut cells: Vec<Vec<(String, Option<image::RgbaImage>)>> = vec![];
    let (mut cw, mut ch) = (64u32, 64u32);
    for s in scenes {
        let images = files::images_dir(dir, s);
        for (v, suffix) in visibilities {
            let reference = super::visibility::series_name(crate::methods::REFERENCE.name(), v);
            let mut top = vec![(
                format!("{s}: {reference}"),
                load(&images.join(files::image(crate::methods::REFERENCE.name(), suffix))),
            )];
            let mut bottom = vec![("FLIP: black 0, white 1".to_string(), None)];
            for m in methods {
                let name = super::visibility::series_name(m, v);
                let row = rows.iter().find(|r| {
                    &r.scene == s && r.method == *m && &r.visibility == v && r.is_default
                });
                let reads = crate::methods::by_name(m).is_ok_and(|d| d.reads_visibility());
                let label = match row {
                    Some(r) => format!("{name}\n{}, RMSE {:.3}", r.label, r.rel_rmse_indirect),
                    None if !reads && !matches!(v.as_str(), "" | "none") => {
                        format!("{m}: reads no\nvisibility")
                    }
                    None => format!("{name}: not run"),
                };
                top.push((label, load(&images.join(files::image(m, suffix)))));
                let flip = row
                    .map(|r| format!("FLIP {:.3}", r.flip))
                    .unwrap_or_default();
                bottom.push((flip, load(&images.join(files::error_map(m, suffix)))));
            }
            for (_, img) in top.iter().chain(&bottom) {
                if let Some(i) = img {
                    cw = cw.max(i.width());
                    ch = ch.max(i.height());
                }
            }
            cells.push(top);
            cells.push(bottom);
        }
    }
    // Small renders are shown enlarged so labels fit.
    let scale = (240 / cw).max(1);
    let (tw, th) = (cw * scale, ch * scale);
    let label_h = 32;
    let cols = cells.iter().map(Vec::len).max().unwrap_or(1) as u32;
    let (w, h) = (
        cols * (tw + 4) + 4,
        cells.len() as u32 * (th + label_h + 4) + 4,
    );
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    for (ri, row) in cells.iter().enumerate() {
        for (ci, (_, img)) in row.iter().enumerate() {
            let Some(img) = img else { continue };
            let (x0, y0) = (
                4 + ci as u32 * (tw + 4),
                4 + ri as u32 * (th + label_h + 4) + label_h,
            );
            for y in 0..img.height() * scale {
                for x in 0..img.width() * scale {
                    let p = img.get_pixel(x / scale, y / scale);
                    let o = (((y0 + y) * w + x0 + x) * 3) as usize;
                    rgb[o..o + 3].copy_from_slice(&p.0[..3]);
                }
            }
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        for (ri, row) in cells.iter().enumerate() {
            for (ci, (label, _)) in row.iter().enumerate() {
                let (x0, y0) = (4 + ci as u32 * (tw + 4), 4 + ri as u32 * (th + label_h + 4));
                for (li, line) in label.lines().enumerate() {
                    root.draw(&Text::new(
                        line.to_string(),
                        (x0 as i32, y0 as i32 + 2 + 15 * li as i32),
                        ("sans-serif", 12).into_font().color(&BLACK),
                    ))
                    .map_err(|e| anyhow!("gallery: {e}"))?;
                }
            }
        }
        root.present().map_err(|e| anyhow!("gallery: {e}"))?;
    }
    let rgba: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    crate::output::write_png(&dir.join(files::GALLERY), w, h, &rgba)
}
