//! Where the bounces of 2 and on gain or lose light against the truth
//! (docs/algorithm.md section 5.9): one bench scene at the bounces axis's
//! frame, a method with 1, 2, 3 and every bounce, against the layers by
//! bounce of the bench's cached truth of every bounce
//! (`OUT_DIR/truth/SCENE/frame-K-bounces-inf.exr`). Prints, per bounce, the
//! light the method adds over what the truth's bounce carries, over the
//! compared pixels and split by the receiver's facing (floor, ceiling,
//! walls).
//!
//!     cargo run --release --example bounce_probe -- [--scenes a,b] [--method M] [--frame K]
//!         [--out-dir DIR] [--grid N] [--no-visibility] [--flicker K]
//!
//! Defaults: `cornell`, `rsm-gather`, frame 3 (the axis's), `out/bench`, the
//! default grid, with the grid's visibility. Half a minute a scene on 2
//! cores. The method's own first bounce is printed beside (`b1`).

use anyhow::{bail, Context as _, Result};
use isr::bench::files::exr_layer as layer;
use isr::bench::truth::{truth_mask, ShadowMaps};
use isr::bounces::{Bounces, BOUNCES, LAYERS};
use isr::renderer::Renderer;
use isr::settings::{Method, RenderSettings};
use isr::vk::{Gpu, GpuOptions};
use std::path::PathBuf;

/// `--flicker K`: the flicker (docs/algorithm.md section 6.3, low-passed
/// first and second differences) of `method` with one bounce against the
/// truth of one bounce, and with every bounce against the truth of every
/// bounce, over frames 0..K of `name` (the bench's cached truth of every
/// bounce at each frame, whose first layer is the truth of one). The
/// bench's own flicker is against the dense reference, which renders the
/// same bounce passes: there the bounce light cancels.
fn flicker(
    gpu: &Gpu,
    name: &str,
    method: &str,
    out_dir: &std::path::Path,
    frames: u32,
) -> Result<()> {
    use isr::bench::metrics::{geometry_mask, Flicker};
    let spec = isr::bench::scenes::SCENES
        .iter()
        .find(|s| s.name == name)
        .context("scene")?;
    let scene = isr::bench::scenes::build(name)?;
    let n = 128 * 128;
    let mut rows = vec![];
    for b in [Bounces::ONE, Bounces::Infinite] {
        let mut s = RenderSettings {
            width: 128,
            height: 128,
            rsm_resolution: 128,
            method: Method::new(isr::methods::by_name(method)?.key().name()),
            ..RenderSettings::DEFAULT
        };
        BOUNCES.set(&mut s, b);
        let mut r = Renderer::new(gpu, &scene, &s)?;
        let mut f = Flicker::new(128, 128);
        for k in 0..frames {
            r.update(&scene.pose_at(spec.start + k as f32 / spec.fps)?)?;
            r.render_frames(1, |_| {})?;
            let out = r.readback()?;
            let path = out_dir.join(format!("truth/{name}/frame-{k}-bounces-inf.exr"));
            let image = exr::prelude::read_all_flat_layers_from_file(&path)
                .with_context(|| format!("{}", path.display()))?;
            let truth = match b {
                Bounces::ONE => layer(&image, LAYERS[0], n),
                _ => layer(&image, "indirect", n),
            }
            .context("truth layer")?;
            f.add(&out.indirect, &truth, &geometry_mask(&out.position))?;
        }
        rows.push((b, f.flicker(), f.second_difference()));
    }
    for (b, first, second) in rows {
        println!(
            "{name} ({method}, {frames} frames): {} against the truth of as many: flicker {:.5}, second difference {:.5}",
            b.words(),
            first.unwrap_or(f64::NAN),
            second.unwrap_or(f64::NAN)
        );
    }
    Ok(())
}

fn main() -> Result<()> {
    let mut scenes = vec!["cornell".to_string()];
    let mut method = "rsm-gather".to_string();
    let mut frame = 3u32;
    let mut out_dir = PathBuf::from("out/bench");
    let mut grid = None;
    let mut novis = false;
    let mut flicker_frames = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().with_context(|| format!("{a} takes a value"));
        match a.as_str() {
            "--scenes" => scenes = value()?.split(',').map(str::to_string).collect(),
            "--method" => method = value()?,
            "--frame" => frame = value()?.parse()?,
            "--out-dir" => out_dir = value()?.into(),
            "--no-visibility" => novis = true,
            "--flicker" => flicker_frames = Some(value()?.parse::<u32>()?),
            "--grid" => grid = Some(value()?.parse::<u32>()?),
            other => bail!(
                "unknown argument {other}; takes --scenes a,b, --method M, --frame K, \
                 --out-dir DIR, --grid N, --no-visibility, --flicker K"
            ),
        }
    }
    let gpu = Gpu::new(&GpuOptions::default())?;
    if let Some(k) = flicker_frames {
        for name in &scenes {
            flicker(&gpu, name, &method, &out_dir, k)?;
        }
        return Ok(());
    }
    for name in &scenes {
        let spec = isr::bench::scenes::SCENES
            .iter()
            .find(|s| s.name == name)
            .context("scene")?;
        let scene = isr::bench::scenes::build(name)?;
        let path = out_dir.join(format!("truth/{name}/frame-{frame}-bounces-inf.exr"));
        let image = exr::prelude::read_all_flat_layers_from_file(&path)
            .with_context(|| format!("{}", path.display()))?;
        let n = 128 * 128;
        let t: Vec<Vec<[f32; 4]>> = LAYERS
            .iter()
            .map(|l| layer(&image, l, n).context("layer"))
            .collect::<Result<_>>()?;
        let direct = layer(&image, "direct", n).context("direct")?;
        let mut imgs = vec![];
        let mut g = None;
        let mut mask = vec![];
        for b in [
            Bounces::ONE,
            Bounces::Count(2),
            Bounces::Count(3),
            Bounces::Infinite,
        ] {
            let mut s = RenderSettings {
                width: 128,
                height: 128,
                rsm_resolution: 128,
                method: Method::new(isr::methods::by_name(&method)?.key().name()),
                ..RenderSettings::DEFAULT
            };
            if let Some(side) = grid {
                isr::voxel_grid::GRID.set(&mut s, side);
            }
            BOUNCES.set(&mut s, b);
            if novis {
                isr::visibility::VISIBILITY.set(&mut s, isr::visibility::Visibility::None);
            }
            let mut r = Renderer::new(&gpu, &scene, &s)?;
            for k in 0..=frame {
                r.update(&scene.pose_at(spec.start + k as f32 / spec.fps)?)?;
                r.render_frames(1, |_| {})?;
            }
            let out = r.readback()?;
            if g.is_none() {
                let views = r.light_views().to_vec();
                let shadows =
                    ShadowMaps::new(&views, r.render_origin(), s.shadow_size(), s.pcf_radius);
                mask = truth_mask(&out, &direct, &shadows).mask;
                g = Some(out.clone());
            }
            imgs.push(out.indirect);
        }
        let g = g.unwrap();
        // Classes by the receiver's normal.
        let class = |k: usize| {
            let nrm = g.normal[k];
            if nrm[1] > 0.7 {
                0
            } else if nrm[1] < -0.7 {
                1
            } else {
                2
            }
        };
        let names = ["floor/up", "ceiling/down", "walls/side"];
        let sum = |x: &[[f32; 4]], c: Option<usize>| -> f64 {
            (0..n)
                .filter(|&k| mask[k] && c.is_none_or(|c| class(k) == c))
                .map(|k| x[k][..3].iter().map(|&v| v as f64).sum::<f64>())
                .sum()
        };
        println!(
            "{name} ({method}, frame {frame}, {} px compared)",
            mask.iter().filter(|&&m| m).count()
        );
        for c in [None, Some(0), Some(1), Some(2)] {
            let label = c.map_or("all", |c| names[c]);
            let t1 = sum(&t[0], c);
            if t1 == 0.0 {
                continue; // no compared pixel faces this way
            }
            let i = imgs.iter().map(|x| sum(x, c)).collect::<Vec<_>>();
            let tl = t.iter().map(|x| sum(x, c)).collect::<Vec<_>>();
            println!(
                "  {label:13} b1 {:.3}  b2 {:.3}  b3 {:.3}  b4+ {:.3}  (truth share b1 {:.2} b2 {:.2} b3 {:.2} b4+ {:.2})",
                i[0] / t1,
                (i[1] - i[0]) / tl[1],
                (i[2] - i[1]) / tl[2],
                (i[3] - i[2]) / tl[3],
                tl[0] / tl.iter().sum::<f64>(),
                tl[1] / tl.iter().sum::<f64>(),
                tl[2] / tl.iter().sum::<f64>(),
                tl[3] / tl.iter().sum::<f64>(),
            );
        }
    }
    Ok(())
}
