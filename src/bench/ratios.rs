//! The ratios a bench run reports (printed, in `results.json` and in
//! `report.md`): the subject's (`methods::SUBJECT`, the paper's method)
//! speedups and errors against the other methods at equal error or time, its
//! front, and flicker ratios, each computed from the rows of one visibility.

use super::rows::Row;
use super::visibility::visibilities;

/// One computed ratio (or error level) and how it came about.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Ratio {
    pub scene: String,
    /// The visibility of the rows it is computed from (`Row::visibility`).
    pub visibility: String,
    pub measure: String,
    pub value: Option<f64>,
    pub detail: String,
}

/// The methods that take N regular VPLs (`--vpls`), in registry order.
pub(super) fn regular() -> Vec<&'static str> {
    crate::methods::REGISTRY
        .iter()
        .filter(|&&d| {
            crate::methods::params_of(d).any(|p| p.name() == crate::regular_vpls::VPLS.name)
        })
        .map(|d| d.key().name())
        .collect()
}

fn find<'a>(rows: &'a [Row], scene: &str, method: &str, vpls: u32) -> Option<&'a Row> {
    rows.iter().find(|r| {
        r.scene == scene && r.method == method && r.param("vpls") == Some(&vpls.to_string())
    })
}

fn ms(r: &Row) -> f64 {
    r.indirect_ms.unwrap_or(f64::NAN)
}

/// The fastest row of `method` in `scene` whose indirect error is at most `error`.
fn fastest_at_most<'a>(rows: &'a [Row], scene: &str, method: &str, error: f64) -> Option<&'a Row> {
    rows.iter()
        .filter(|r| r.scene == scene && r.method == method && r.indirect_ms.is_some())
        .filter(|r| r.rel_rmse_indirect <= error)
        .min_by(|a, b| ms(a).total_cmp(&ms(b)))
}

/// The lowest-error row of `method` in `scene` no slower than `time` ms.
fn best_within<'a>(rows: &'a [Row], scene: &str, method: &str, time: f64) -> Option<&'a Row> {
    rows.iter()
        .filter(|r| {
            r.scene == scene && r.method == method && r.indirect_ms.is_some_and(|t| t <= time)
        })
        .min_by(|a, b| a.rel_rmse_indirect.total_cmp(&b.rel_rmse_indirect))
}

fn describe(r: &Row) -> String {
    format!(
        "{} {} ({:.1} ms, RMSE {:.3})",
        r.method,
        r.label,
        ms(r),
        r.rel_rmse_indirect
    )
}

/// The rows of `rows` rendered with visibility `v`.
pub(super) fn with_visibility(rows: &[Row], v: &str) -> Vec<Row> {
    rows.iter().filter(|r| r.visibility == v).cloned().collect()
}

/// The subject's name (`methods::SUBJECT`).
fn subject() -> &'static str {
    crate::methods::SUBJECT.name()
}

/// The ratios per scene and visibility (each from the rows of one
/// visibility alone): the subject's indirect-time speedup over each regular
/// method with 256 and 4096 VPLs at equal or lower error, the error it
/// reaches in the time of 256 regular VPLs, its front, and its flicker
/// against 256 and 4096 regular VPLs.
pub fn ratios(rows: &[Row]) -> Vec<Ratio> {
    visibilities(rows)
        .into_iter()
        .flat_map(|v| ratios_of(&with_visibility(rows, v), v))
        .collect()
}

/// [`ratios`] of rows of one visibility, `visibility`.
fn ratios_of(rows: &[Row], visibility: &str) -> Vec<Ratio> {
    let mut scenes: Vec<&str> = vec![];
    for r in rows {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    let mut out = vec![];
    for s in scenes {
        let mut push = |measure: String, value: Option<f64>, detail: String| {
            out.push(Ratio {
                scene: s.into(),
                visibility: visibility.into(),
                measure,
                value,
                detail,
            })
        };
        let subject = subject();
        for (base, n) in regular().into_iter().flat_map(|b| [(b, 256), (b, 4096)]) {
            let Some(b) = find(rows, s, base, n) else {
                continue;
            };
            let m = format!("speedup of {subject} over {base} {n} at equal or lower error");
            match fastest_at_most(rows, s, subject, b.rel_rmse_indirect) {
                Some(h) => push(
                    m,
                    Some(ms(b) / ms(h)),
                    format!("{} against {}", describe(h), describe(b)),
                ),
                None => push(
                    m,
                    None,
                    format!(
                        "no {subject} setting reaches RMSE {:.3}",
                        b.rel_rmse_indirect
                    ),
                ),
            }
        }
        for base in regular() {
            let Some(b) = find(rows, s, base, 256) else {
                continue;
            };
            let m = format!("{subject} error in the time of {base} 256 (relative to its error)");
            match best_within(rows, s, subject, ms(b)) {
                Some(h) => push(
                    m,
                    Some(h.rel_rmse_indirect / b.rel_rmse_indirect),
                    format!("{} against {}", describe(h), describe(b)),
                ),
                None => push(
                    m,
                    None,
                    format!("every {subject} setting is slower than {:.1} ms", ms(b)),
                ),
            }
        }
        let (front, detail) = front(rows, s);
        push(
            format!(
                "least speedup of {subject} over any other method's point at equal or lower error"
            ),
            front,
            detail,
        );
        let default = rows
            .iter()
            .find(|r| r.scene == s && r.method == subject && r.is_default);
        for base in regular() {
            for n in [256, 4096] {
                let (Some(h), Some(b)) = (default, find(rows, s, base, n)) else {
                    continue;
                };
                if let (Some(fh), Some(fb)) = (h.flicker, b.flicker) {
                    push(
                        format!("flicker of {subject} (default) / {base} {n}"),
                        Some(fh / fb),
                        format!("{fh:.4} against {fb:.4}"),
                    );
                }
            }
        }
        // What the flicker measure must tell apart (section 6.3): 64
        // regular VPLs pop as the light moves, 4096 hardly do.
        for base in regular() {
            let Some((low, pixel)) = flicker_64_over_4096(rows, s, base) else {
                continue;
            };
            push(
                format!("flicker of {base} 64 / {base} 4096"),
                Some(low.0 / low.1),
                format!(
                    "{:.4} against {:.4}; per pixel, without the low-pass, {}",
                    low.0,
                    low.1,
                    pixel.map_or("-".into(), |(a, b)| format!(
                        "{a:.4} against {b:.4} ({:.2})",
                        a / b
                    ))
                ),
            );
        }
    }
    out
}

/// Flicker (low-passed) of `base` with 64 and with 4096 VPLs in `scene`,
/// and the same per pixel where the rows have it.
#[allow(clippy::type_complexity)]
pub(super) fn flicker_64_over_4096(
    rows: &[Row],
    scene: &str,
    base: &str,
) -> Option<((f64, f64), Option<(f64, f64)>)> {
    let (a, b) = (find(rows, scene, base, 64)?, find(rows, scene, base, 4096)?);
    let low = (a.flicker?, b.flicker?);
    let pixel = a.flicker_pixel.zip(b.flicker_pixel);
    Some((low, pixel))
}

/// Whether the subject's curve lies below every other method's: over every
/// point of every other method in `scene` but the reference, the speedup of
/// the subject's fastest point at equal or lower error; the least of them,
/// the point it was, and how many points lie below every error of the
/// subject (where it has no point to compare).
fn front(rows: &[Row], scene: &str) -> (Option<f64>, String) {
    let (subject, reference) = (subject(), crate::methods::REFERENCE.name());
    let mut least: Option<(f64, &Row, &Row)> = None;
    let (mut reached, mut unreached) = (0, 0);
    let others = rows.iter().filter(|r| {
        r.scene == scene && r.indirect_ms.is_some() && r.method != subject && r.method != reference
    });
    for b in others {
        let Some(h) = fastest_at_most(rows, scene, subject, b.rel_rmse_indirect) else {
            unreached += 1;
            continue;
        };
        reached += 1;
        let v = ms(b) / ms(h);
        if least.is_none_or(|(l, ..)| v < l) {
            least = Some((v, h, b));
        }
    }
    let below = format!(
        "{unreached} of {} points below every {subject} error",
        reached + unreached
    );
    match least {
        Some((v, h, b)) => (
            Some(v),
            format!("{} against {}; {below}", describe(h), describe(b)),
        ),
        None => (None, below),
    }
}

pub(super) fn fmt_value(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{v:.3}"))
}

/// The ratios as a plain-text table (printed by `isr bench` and `cargo bench`).
pub fn ratios_text(ratios: &[Ratio]) -> String {
    let mut out = String::new();
    for r in ratios {
        out += &format!(
            "{:<14} {:<10} {:<72} {:>8}  {}\n",
            r.scene,
            r.visibility,
            r.measure,
            fmt_value(r.value),
            r.detail
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(method: &str, vpls: Option<u32>, ms: f64, err: f64, flicker: f64) -> Row {
        let mut r = super::super::rows::tests_support::row("k");
        r.method = method.into();
        if let Some(n) = vpls {
            r.params.insert("vpls".into(), n.to_string());
        }
        r.indirect_ms = Some(ms);
        r.rel_rmse_indirect = err;
        r.flicker = Some(flicker);
        r.is_default = method == "hisr" && ms == 10.0;
        r
    }

    #[test]
    fn ratios_are_of_the_rows_of_one_visibility() {
        let mut rows = vec![
            row("multires-splat", Some(256), 100.0, 0.2, 0.04),
            row("hisr", None, 10.0, 0.15, 0.01),
        ];
        // With the grid: a HISR point far faster at the same error, which
        // the ratios without it must not see.
        let mut fast = row("hisr", None, 1.0, 0.15, 0.01);
        fast.visibility = "voxels 64".into();
        let mut splat = row("multires-splat", Some(256), 200.0, 0.2, 0.04);
        splat.visibility = "voxels 64".into();
        rows.extend([fast, splat]);
        let r = ratios(&rows);
        let get = |v: &str| {
            r.iter()
                .find(|x| {
                    x.visibility == v
                        && x.measure.starts_with("speedup of hisr over multires-splat")
                })
                .unwrap()
                .value
        };
        assert_eq!(get("none"), Some(10.0));
        assert_eq!(get("voxels 64"), Some(200.0));
    }

    #[test]
    fn flicker_of_64_over_4096_vpls_per_method() {
        let mut a = row("multires-gather", Some(64), 5.0, 0.5, 0.06);
        a.flicker_pixel = Some(0.09);
        let mut b = row("multires-gather", Some(4096), 200.0, 0.1, 0.02);
        b.flicker_pixel = Some(0.1);
        // rsm-gather has no 4096 row: no ratio.
        let c = row("rsm-gather", Some(64), 5.0, 0.5, 0.06);
        let r = ratios(&[a, b, c]);
        let f: Vec<&Ratio> = r.iter().filter(|x| x.measure.contains("64 / ")).collect();
        assert_eq!(f.len(), 1, "{f:?}");
        assert_eq!(
            f[0].measure,
            "flicker of multires-gather 64 / multires-gather 4096"
        );
        assert!((f[0].value.unwrap() - 3.0).abs() < 1e-12);
        assert!(
            f[0].detail.ends_with("0.0900 against 0.1000 (0.90)"),
            "{}",
            f[0].detail
        );
    }

    #[test]
    fn ratios_pick_the_fastest_hisr_at_equal_or_lower_error() {
        let rows = vec![
            row("multires-splat", Some(256), 100.0, 0.2, 0.04),
            row("multires-gather", Some(256), 80.0, 0.2, 0.04),
            row("multires-gather", Some(4096), 400.0, 0.08, 0.01),
            row("hisr", None, 5.0, 0.3, 0.02),
            row("hisr", None, 10.0, 0.15, 0.01),
            row("hisr", None, 50.0, 0.07, 0.005),
        ];
        let r = ratios(&rows);
        let get = |m: &str| r.iter().find(|x| x.measure.starts_with(m)).unwrap().value;
        // 0.15 <= 0.2 at 10 ms: 100 / 10.
        assert_eq!(get("speedup of hisr over multires-splat 256"), Some(10.0));
        // 0.07 <= 0.08 at 50 ms: 400 / 50.
        assert_eq!(get("speedup of hisr over multires-gather 4096"), Some(8.0));
        // Within 100 ms the best HISR error is 0.07: 0.07 / 0.2.
        let e = get("hisr error in the time of multires-splat 256").unwrap();
        assert!((e - 0.35).abs() < 1e-12);
        assert_eq!(
            get("flicker of hisr (default) / multires-gather 256"),
            Some(0.25)
        );
        assert_eq!(
            get("flicker of hisr (default) / multires-gather 4096"),
            Some(1.0)
        );
        // Every other point: multires-gather 256 (80 ms, 0.2) against hisr
        // 10 ms is the least, 8x; none lies below hisr's best error 0.07.
        let front = |rows: &[Row]| {
            let r = ratios(rows);
            let f = r
                .iter()
                .find(|x| x.measure.starts_with("least speedup of hisr"))
                .unwrap();
            (f.value, f.detail.clone())
        };
        let (value, detail) = front(&rows);
        assert_eq!(value, Some(8.0));
        assert!(detail.ends_with("0 of 3 points below every hisr error"));
        // A cheap coarse point HISR cannot beat, and one below its errors.
        let mut more = rows.clone();
        more.push(row("rsm-splat-restricted", Some(64), 4.0, 0.5, 0.1));
        more.push(row("rsm-gather", Some(4096), 900.0, 0.01, 0.1));
        // 0.3 <= 0.5 at 5 ms: 4 / 5.
        let (value, detail) = front(&more);
        assert_eq!(value, Some(0.8));
        assert!(detail.ends_with("1 of 5 points below every hisr error"));
    }
}
