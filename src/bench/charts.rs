//! The bench's charts (plotters; each drawn once to SVG and once to PNG from
//! the same code) and the gallery. Text uses DejaVu Sans compiled into the
//! binary (`dejavu` crate), registered with plotters' ab_glyph backend, so no
//! system font is needed.

use super::files::Chart;
use super::rows::Row;
use anyhow::{anyhow, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Registers the embedded font as "sans-serif" (once; later calls do nothing).
pub fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The font is a valid TTF shipped by the crate; failure would only
        // mean text is not drawn, so it is not fatal.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// A fixed colour per method, the same in every chart
/// (`methods::Descriptor::color`); black for a name no method has.
pub fn method_color(method: &str) -> RGBColor {
    match crate::methods::by_name(method) {
        Ok(d) => {
            let [r, g, b] = d.color();
            RGBColor(r, g, b)
        }
        Err(_) => RGBColor(0, 0, 0),
    }
}

type Draw<'a> = dyn Fn(&DrawingArea<SVGBackend, Shift>) -> Result<()> + 'a;
type DrawPng<'a> = dyn Fn(&DrawingArea<BitMapBackend, Shift>) -> Result<()> + 'a;

/// Draws `chart` into `dir` as its SVG and its PNG (the same function for
/// both backends, written atomically).
fn both(dir: &Path, chart: Chart, size: (u32, u32), svg: &Draw, png: &DrawPng) -> Result<()> {
    let stem = dir.join(chart.stem());
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        svg(&root)?;
        root.present()
            .map_err(|e| anyhow!("drawing {}: {e}", stem.display()))?;
    }
    crate::output::write_text(&dir.join(chart.svg()), &text)?;
    let mut rgb = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        png(&root)?;
        root.present()
            .map_err(|e| anyhow!("drawing {}: {e}", stem.display()))?;
    }
    let rgba: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    crate::output::write_png(&dir.join(chart.png()), size.0, size.1, &rgba)
}

/// Grid of (rows, columns) for `n` panels.
fn grid(n: usize) -> (usize, usize) {
    let cols = n.clamp(1, 3);
    (n.div_ceil(cols).max(1), cols)
}

fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 0.1..1.0;
    }
    // At least two powers of ten in range, so a log axis has labels.
    if hi / lo < 10.0 {
        lo = 10f64.powf(lo.log10().floor());
        hi = 10f64.powf(hi.log10().ceil()).max(lo * 10.0);
        return lo..hi;
    }
    (lo / 1.5)..(hi * 1.5)
}

/// A tick label with two significant digits ("0.03", "120").
fn short(v: f64) -> String {
    if v <= 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (1 - v.log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

/// The points of `sorted` (by x) that no earlier point matches or beats in y:
/// a method's front, its least y at each x. A dense sweep's points joined in
/// order zigzag; the line follows the front and every point gets a dot.
fn front(sorted: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut best = f64::INFINITY;
    sorted
        .iter()
        .filter(|&&(_, y)| {
            let keep = y < best;
            best = best.min(y);
            keep
        })
        .copied()
        .collect()
}

/// A curve of the charts: a method's rows of one visibility (`Row::visibility`).
#[derive(Clone, Copy, PartialEq)]
struct Series<'a> {
    method: &'a str,
    visibility: &'a str,
}

impl Series<'_> {
    fn of(r: &Row) -> Series<'_> {
        Series {
            method: &r.method,
            visibility: &r.visibility,
        }
    }

    /// Whether it renders with indirect visibility: drawn dashed, its dots
    /// hollow, in its method's colour.
    fn with_visibility(&self) -> bool {
        !matches!(self.visibility, "" | "none")
    }

    /// Its legend entry: `hisr`, `hisr + voxels 64`.
    fn name(&self) -> String {
        super::visibility::series_name(self.method, self.visibility)
    }

    /// Its line through `points`.
    fn line<DB: DrawingBackend>(
        &self,
        chart: &mut ChartContext<DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>,
        points: Vec<(f64, f64)>,
    ) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let style = method_color(self.method).stroke_width(2);
        match self.with_visibility() {
            true => chart.draw_series(DashedLineSeries::new(points, 7, 4, style)),
            false => chart.draw_series(LineSeries::new(points, style)),
        }
        .map_err(|e| anyhow!("{e}"))?;
        Ok(())
    }

    /// Its dot at `p`.
    fn dot<C>(&self, p: C) -> Circle<C, i32> {
        let color = method_color(self.method);
        match self.with_visibility() {
            true => Circle::new(p, 3, color.stroke_width(1)),
            false => Circle::new(p, 3, color.filled()),
        }
    }
}

/// The grid of a chart: a cell per scene and one for the legend, which so
/// never covers a point or a bar.
fn legend_grid(scenes: usize) -> (usize, usize) {
    grid(scenes + 1)
}

/// `items` in order of their method's first appearance, stably: a method's
/// rows of every visibility side by side, as `rows` orders them (without
/// visibility first).
fn by_method<T>(items: &mut [T], method: impl Fn(&T) -> &str) {
    let mut order: Vec<String> = vec![];
    for i in items.iter() {
        if !order.iter().any(|m| m == method(i)) {
            order.push(method(i).to_string());
        }
    }
    items.sort_by_key(|i| order.iter().position(|m| m == method(i)));
}

/// Panels of (x, y) curves, one per method and visibility over its sweep,
/// log-log: a line along its front (`front`; dashed with visibility), a dot
/// per point; the legend in a cell of its own. With `reference`, each dense
/// reference's y (one per visibility) is a dashed line across each panel
/// (against the truth: the model error, which no VPL method goes far below).
fn curves<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[Row],
    scenes: &[String],
    title: &str,
    y_label: &str,
    y: &dyn Fn(&Row) -> Option<f64>,
    reference: bool,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| anyhow!("{e}"))?;
    let panels = root.split_evenly(legend_grid(scenes.len()));
    if let Some(cell) = panels.get(scenes.len()) {
        legend_panel(cell, &series_in(rows))?;
    }
    for (scene, panel) in scenes.iter().zip(panels.iter()) {
        let pts: Vec<&Row> = rows
            .iter()
            .filter(|row| &row.scene == scene && row.method != crate::methods::REFERENCE.name())
            .filter(|row| {
                row.indirect_ms.is_some_and(|v| v > 0.0) && y(row).is_some_and(|v| v > 0.0)
            })
            .collect();
        let floors: Vec<(String, f64)> = rows
            .iter()
            .filter(|row| {
                reference && &row.scene == scene && row.method == crate::methods::REFERENCE.name()
            })
            .filter_map(|row| {
                let name = super::visibility::series_name("dense reference", &row.visibility);
                Some((name, y(row).filter(|v| *v > 0.0)?))
            })
            .collect();
        let xr = log_range(pts.iter().filter_map(|r| r.indirect_ms));
        let yr = log_range(
            pts.iter()
                .filter_map(|r| y(r))
                .chain(floors.iter().map(|f| f.1)),
        );
        let mut chart = ChartBuilder::on(panel)
            .caption(scene, ("sans-serif", 18))
            .margin(8)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(xr.clone().log_scale(), yr.clone().log_scale())
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc("indirect ms")
            .y_desc(y_label)
            .x_labels(6)
            .y_labels(6)
            .x_label_formatter(&|v| short(*v))
            .y_label_formatter(&|v| short(*v))
            .label_style(("sans-serif", 12))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        let mut series: Vec<Series> = vec![];
        for p in &pts {
            if !series.contains(&Series::of(p)) {
                series.push(Series::of(p));
            }
        }
        for s in series {
            let mut line: Vec<(f64, f64)> = pts
                .iter()
                .filter(|p| Series::of(p) == s)
                .filter_map(|p| Some((p.indirect_ms?, y(p)?)))
                .collect();
            line.sort_by(|a, b| a.0.total_cmp(&b.0));
            s.line(&mut chart, front(&line))?;
            chart
                .draw_series(line.iter().map(|&p| s.dot(p)))
                .map_err(|e| anyhow!("{e}"))?;
        }
        for (name, v) in floors {
            let ends = vec![(xr.start, v), (xr.end, v)];
            chart
                .draw_series(DashedLineSeries::new(ends, 6, 4, BLACK.stroke_width(1)))
                .map_err(|e| anyhow!("{e}"))?;
            // Above its line: below it, the lowest would meet the axis.
            let font = ("sans-serif", 11).into_font().color(&BLACK);
            let above = font.pos(Pos::new(HPos::Left, VPos::Bottom));
            chart
                .draw_series(std::iter::once(Text::new(
                    format!("{name} {}", short(v)),
                    (xr.start * 1.05, v),
                    above,
                )))
                .map_err(|e| anyhow!("{e}"))?;
        }
    }
    Ok(())
}

/// Every series of `rows` but the references', in first appearance, a
/// method's side by side.
fn series_in(rows: &[Row]) -> Vec<Series<'_>> {
    let mut out: Vec<Series> = vec![];
    for r in rows {
        if r.method != crate::methods::REFERENCE.name() && !out.contains(&Series::of(r)) {
            out.push(Series::of(r));
        }
    }
    by_method(&mut out, |s| s.method);
    out
}

/// Where a legend cell of `size` pixels puts its `n` rows: the left of its
/// marks, the first row's y and the step between rows (the rows centred).
fn legend_rows((w, h): (u32, u32), n: usize) -> (i32, i32, i32) {
    let step = (h as i32 / (n as i32 + 1)).clamp(12, 22);
    (w as i32 / 6, (h as i32 - step * n as i32) / 2, step)
}

/// The legend of `series`, drawn alone in a free cell of the grid: a
/// series with visibility dashed with a hollow dot, as its curve.
fn legend_panel<DB: DrawingBackend>(cell: &DrawingArea<DB, Shift>, series: &[Series]) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let (x0, y0, step) = legend_rows(cell.dim_in_pixel(), series.len());
    for (i, s) in series.iter().enumerate() {
        let y = y0 + step * i as i32;
        let style = method_color(s.method).stroke_width(3);
        let dashes = match s.with_visibility() {
            true => vec![(x0, x0 + 9), (x0 + 19, x0 + 28)],
            false => vec![(x0, x0 + 28)],
        };
        for (a, b) in dashes {
            cell.draw(&PathElement::new(vec![(a, y), (b, y)], style))
                .map_err(|e| anyhow!("{e}"))?;
        }
        cell.draw(&s.dot((x0 + 14, y)))
            .map_err(|e| anyhow!("{e}"))?;
        cell.draw(&Text::new(
            s.name(),
            (x0 + 38, y - 8),
            ("sans-serif", 15).into_font(),
        ))
        .map_err(|e| anyhow!("{e}"))?;
    }
    Ok(())
}

/// `speed_vs_error.svg/.png`: indirect ms against relative RMSE of the
/// indirect image, one panel per scene (section 6.5).
pub fn speed_vs_error(dir: &Path, rows: &[Row], scenes: &[String]) -> Result<()> {
    let (r, c) = legend_grid(scenes.len());
    let size = (480 * c as u32, 400 * r as u32 + 40);
    let title = "indirect time against error (log-log; lower left is better)";
    let y = |r: &Row| Some(r.rel_rmse_indirect);
    both(
        dir,
        Chart::SpeedVsError,
        size,
        &|a| {
            curves(
                a,
                rows,
                scenes,
                title,
                "relative RMSE (indirect)",
                &y,
                false,
            )
        },
        &|a| {
            curves(
                a,
                rows,
                scenes,
                title,
                "relative RMSE (indirect)",
                &y,
                false,
            )
        },
    )
}

/// `speed_vs_truth.svg/.png`: indirect ms against relative RMSE of the
/// indirect image against the path-traced truth, over the pixels its mask
/// keeps, with the dense reference's (section 6.6); the title says the
/// truth's bounces.
pub fn speed_vs_truth(dir: &Path, rows: &[Row], scenes: &[String]) -> Result<()> {
    let (r, c) = legend_grid(scenes.len());
    let size = (480 * c as u32, 400 * r as u32 + 40);
    let title = &format!(
        "indirect time against error from {} (log-log)",
        super::bounces::rows_truth_words(rows)
    );
    let y = |r: &Row| r.truth.rel_rmse_indirect;
    let label = "relative RMSE against the truth";
    both(
        dir,
        Chart::SpeedVsTruth,
        size,
        &|a| curves(a, rows, scenes, title, label, &y, true),
        &|a| curves(a, rows, scenes, title, label, &y, true),
    )
}

/// `flicker.svg/.png`: flicker (section 6.3) against indirect ms.
pub fn flicker(dir: &Path, rows: &[Row], scenes: &[String]) -> Result<()> {
    let (r, c) = legend_grid(scenes.len());
    let size = (480 * c as u32, 400 * r as u32 + 40);
    let title = "flicker against indirect time (log-log; lower left is better)";
    let y = |r: &Row| r.flicker;
    both(
        dir,
        Chart::Flicker,
        size,
        &|a| curves(a, rows, scenes, title, "flicker (indirect)", &y, false),
        &|a| curves(a, rows, scenes, title, "flicker (indirect)", &y, false),
    )
}

/// The passes' colours: Kelly's colours of maximum contrast (less white) and
/// four more, at least one for each pass a full bench draws (22), so that
/// neighbouring passes in a bar stay apart (with `Palette99`,
/// `voxel-grid` and `composite` came out alike).
const PASS_COLOURS: [(u8, u8, u8); 24] = [
    (0xF3, 0xC3, 0x00),
    (0x87, 0x56, 0x92),
    (0xF3, 0x84, 0x00),
    (0xA1, 0xCA, 0xF1),
    (0xBE, 0x00, 0x32),
    (0xC2, 0xB2, 0x80),
    (0x84, 0x84, 0x82),
    (0x00, 0x88, 0x56),
    (0xE6, 0x8F, 0xAC),
    (0x00, 0x67, 0xA5),
    (0xF9, 0x93, 0x79),
    (0x60, 0x4E, 0x97),
    (0xF6, 0xA6, 0x00),
    (0xB3, 0x44, 0x6C),
    (0xDC, 0xD3, 0x00),
    (0x88, 0x2D, 0x17),
    (0x8D, 0xB6, 0x00),
    (0x65, 0x45, 0x22),
    (0xE2, 0x58, 0x22),
    (0x2B, 0x3D, 0x26),
    (0x22, 0x22, 0x22),
    (0x00, 0xA6, 0xA6),
    (0xFF, 0x4F, 0xFF),
    (0x7F, 0xFF, 0xD4),
];

/// Stacked per-pass times of each method at its default, one panel per scene.
fn stacked<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[Row],
    scenes: &[String],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
    let root = root
        .titled(
            "per-pass GPU time at each method's default (median ms)",
            ("sans-serif", 22),
        )
        .map_err(|e| anyhow!("{e}"))?;
    let panels = root.split_evenly(legend_grid(scenes.len()));
    // The passes of the bars (the references' own are not drawn).
    let is_bar = |r: &&Row| r.is_default && r.method != crate::methods::REFERENCE.name();
    let passes: Vec<String> = super::rows::pass_names(rows)
        .into_iter()
        .filter(|p| rows.iter().filter(is_bar).any(|r| r.passes.contains_key(p)))
        .collect();
    let palette = |i: usize| {
        let (r, g, b) = PASS_COLOURS[i % PASS_COLOURS.len()];
        RGBAColor(r, g, b, 1.0)
    };
    if let Some(cell) = panels.get(scenes.len()) {
        pass_legend(cell, &passes, &palette)?;
    }
    for (scene, panel) in scenes.iter().zip(panels.iter()) {
        let mut bars: Vec<&Row> = rows
            .iter()
            .filter(|r| &r.scene == scene)
            .filter(is_bar)
            .collect();
        by_method(&mut bars, |r| &r.method);
        let max = bars
            .iter()
            .filter_map(|r| r.total_ms)
            .fold(1e-3f64, f64::max)
            * 1.1;
        let n = bars.len().max(1);
        // Horizontal bars: names (a method's, with its visibility where it
        // has one: `hisr + voxels 64`) fit on the left.
        let names: Vec<String> = bars.iter().map(|r| Series::of(r).name()).collect();
        let longest = names.iter().map(|n| n.chars().count()).max().unwrap_or(0);
        let mut chart = ChartBuilder::on(panel)
            .caption(scene, ("sans-serif", 18))
            .margin(8)
            .x_label_area_size(36)
            .y_label_area_size((7 * longest as u32 + 12).max(130))
            .build_cartesian_2d(0f64..max, 0f64..n as f64)
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(4 * n + 1)
            .y_label_formatter(&|y| {
                // One label at each bar's middle.
                let i = y.floor() as usize;
                if (y - i as f64 - 0.5).abs() < 0.01 {
                    names.get(i).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .x_desc("ms")
            // Few, short labels: a panel is narrow.
            .x_labels(5)
            .x_label_formatter(&|v| short(*v))
            .label_style(("sans-serif", 12))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        for (pi, pass) in passes.iter().enumerate() {
            let color = palette(pi);
            let rects: Vec<Rectangle<(f64, f64)>> = bars
                .iter()
                .enumerate()
                .filter_map(|(i, r)| {
                    let ms = *r.passes.get(pass)?;
                    let below: f64 = passes[..pi].iter().filter_map(|p| r.passes.get(p)).sum();
                    Some(Rectangle::new(
                        [(below, i as f64 + 0.15), (below + ms, i as f64 + 0.85)],
                        color.filled(),
                    ))
                })
                .collect();
            if rects.is_empty() {
                continue;
            }
            chart.draw_series(rects).map_err(|e| anyhow!("{e}"))?;
        }
    }
    Ok(())
}

/// The legend of the per-pass chart, alone in a free cell: a swatch per pass.
fn pass_legend<DB: DrawingBackend>(
    cell: &DrawingArea<DB, Shift>,
    passes: &[String],
    palette: &dyn Fn(usize) -> RGBAColor,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let (x0, y0, step) = legend_rows(cell.dim_in_pixel(), passes.len());
    for (i, pass) in passes.iter().enumerate() {
        let y = y0 + step * i as i32;
        cell.draw(&Rectangle::new(
            [(x0, y - 6), (x0 + 14, y + 6)],
            palette(i).filled(),
        ))
        .map_err(|e| anyhow!("{e}"))?;
        cell.draw(&Text::new(
            pass.clone(),
            (x0 + 24, y - 8),
            ("sans-serif", 15).into_font(),
        ))
        .map_err(|e| anyhow!("{e}"))?;
    }
    Ok(())
}

/// `passes.svg/.png`.
pub fn passes(dir: &Path, rows: &[Row], scenes: &[String]) -> Result<()> {
    let (r, c) = legend_grid(scenes.len());
    let size = (480 * c as u32, 460 * r as u32 + 40);
    both(
        dir,
        Chart::Passes,
        size,
        &|a| stacked(a, rows, scenes),
        &|a| stacked(a, rows, scenes),
    )
}

#[cfg(test)]
mod tests {
    use super::front;

    #[test]
    fn the_front_keeps_only_points_lower_than_every_faster_one() {
        let sorted = [(1.0, 0.5), (2.0, 0.6), (3.0, 0.4), (4.0, 0.4), (5.0, 0.1)];
        assert_eq!(front(&sorted), [(1.0, 0.5), (3.0, 0.4), (5.0, 0.1)]);
        assert!(front(&[]).is_empty());
    }
}
