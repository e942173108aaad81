//! One result row per (scene, method, parameters), the journal that makes a
//! run resumable (`rows.jsonl`, a row appended as it finishes), and the
//! `results.json` / `results.csv` written from it.

use anyhow::{Context as _, Result};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, HashSet};
use std::io::Write as _;
use std::path::Path;

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Row {
    /// Identifies the row across runs: scene, method, label, size, RSM, frames.
    pub key: String,
    pub scene: String,
    pub method: String,
    /// The indirect visibility it rendered with (`bench::visibility`):
    /// `none`, or `voxels N` (the grid's side). Empty in rows journalled
    /// before the axis; the run fills it in from the row's key.
    #[serde(default)]
    pub visibility: String,
    /// The bounces of the truth its `truth` errors are against
    /// (`bench::bounces`: `1`, `3`, `inf`; `--bounces`), as many as the
    /// methods that render bounces render. Rows journalled before there was
    /// a choice were against one bounce.
    #[serde(default = "one_bounce")]
    pub bounces: String,
    pub label: String,
    pub is_default: bool,
    /// The value of every parameter the method reads, by option name
    /// (`vpls`, `tau`, `max-depth`: derived defaults resolved), as text.
    #[serde(default)]
    pub params: BTreeMap<String, String>,
    pub width: u32,
    pub height: u32,
    pub rsm: u32,
    /// Animation frames rendered and compared.
    pub frames: u32,
    /// Median and min over all timed frames of the indirect passes' sum (section 6.2).
    pub indirect_ms: Option<f64>,
    pub indirect_ms_min: Option<f64>,
    pub total_ms: Option<f64>,
    /// Median ms of every pass, by name.
    pub passes: BTreeMap<String, f64>,
    /// Fragment-shader invocations of the indirect passes (last frame).
    pub fragment_invocations: Option<u64>,
    /// Light-patch (VPL) evaluations in the last frame, where known.
    pub light_patch_evals: Option<u64>,
    /// Means over the frames, against the dense reference of the same frame.
    pub rel_rmse_indirect: f64,
    pub rel_rmse_final: f64,
    pub flip: f64,
    /// Section 6.3 on the indirect image, low-passed (first and second
    /// differences); `None` for a single frame.
    pub flicker: Option<f64>,
    pub flicker_second: Option<f64>,
    /// Section 6.3 on the final image.
    pub flicker_final: Option<f64>,
    /// The indirect image's first difference per pixel, without the
    /// low-pass (the measure before it, for comparison).
    #[serde(default)]
    pub flicker_pixel: Option<f64>,
    /// GPU memory the method's resources take: the allocator's total with the
    /// method's renderer minus that with `--method none`.
    pub gpu_memory_bytes: Option<i64>,
    /// Against the path-traced truth (docs/algorithm.md section 6.6); empty
    /// in rows journalled before the bench traced it.
    #[serde(default)]
    pub truth: TruthErrors,
}

/// A row's error against the path-traced truth of the same frames, and (in
/// the dense reference's row, which the truth is traced beside) what the
/// truth was.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct TruthErrors {
    /// Mean over the frames of the indirect image's relative RMSE against
    /// the truth, over the pixels the truth mask keeps. The reference's is
    /// the model error every VPL method shares (no indirect visibility).
    pub rel_rmse_indirect: Option<f64>,
    /// The truth's samples per pixel, its measured noise (relative RMSE of
    /// its Monte Carlo noise) and the fraction of pixels with geometry its
    /// mask leaves out, means over the frames (the reference's row).
    pub spp: Option<f64>,
    pub noise: Option<f64>,
    pub left_out: Option<f64>,
    /// The reference's row: the dense reference with exact visibility
    /// (`visibility`) against the truth at the middle frame, the floor of
    /// the VPL model (its texel-sized VPLs alone).
    #[serde(default)]
    pub floor: Option<f64>,
    /// A row of the bounces axis (`bounce_axis`), whose
    /// `rel_rmse_indirect` is against the truth of every bounce: its error
    /// against the truth of its own bounces; the light its bounces 2..N add
    /// (`I_N - I_1`) over what they add in the truth (`T_N - T_1`), summed
    /// over the mask (1: as much; none for one bounce); and
    /// the truth's share of the indirect light of bounces 1, 2, 3 and 4 on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub same_bounces: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extra_light: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shares: Option<Vec<f64>>,
}

/// What [`read_journal`] found: the rows, and the lines it skipped.
#[derive(Debug, Default)]
pub struct Journal {
    pub rows: Vec<Row>,
    /// Each line that is not a row (cut off by an interruption, or any
    /// other bytes): its number from 1 and why.
    pub skipped: Vec<(usize, String)>,
}

impl Journal {
    /// One line per skipped line of `path`, for stderr.
    pub fn warnings(&self, path: &Path) -> Vec<String> {
        self.skipped
            .iter()
            .map(|(n, why)| {
                format!(
                    "warning: {} line {n} is skipped ({why}); its row, if any, is measured again",
                    path.display()
                )
            })
            .collect()
    }
}

/// The rows already finished in `path` (a missing file is an empty journal).
/// A line that is not a row, whatever its bytes (a line cut off by an
/// interruption, even inside a character), is skipped and listed.
pub fn read_journal(path: &Path) -> Result<Journal> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Journal::default()),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    let mut journal = Journal::default();
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let why = match std::str::from_utf8(line) {
            Err(_) => "not valid UTF-8: cut off, or not written by isr bench".to_string(),
            Ok(text) => match serde_json::from_str::<Row>(text) {
                Ok(row) => {
                    journal.rows.push(row);
                    continue;
                }
                Err(e) if e.is_eof() => "cut off".to_string(),
                Err(e) => format!("not a row: {e}"),
            },
        };
        journal.skipped.push((i + 1, why));
    }
    Ok(journal)
}

/// Appends `row` as one line and flushes it to disk, so an interruption
/// keeps it.
pub fn append(path: &Path, row: &Row) -> Result<()> {
    append_line(path, row).with_context(|| format!("cannot append a row to {}", path.display()))
}

fn append_line(path: &Path, row: &Row) -> Result<()> {
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)?;
    let mut line = serde_json::to_string(row)?;
    line.push('\n');
    // After an interrupted write the last line is torn: start a new one.
    let len = f.metadata()?.len();
    if len > 0 {
        use std::io::{Read as _, Seek as _};
        let mut r = std::fs::File::open(path)?;
        r.seek(std::io::SeekFrom::Start(len - 1))?;
        let mut last = [0u8];
        r.read_exact(&mut last)?;
        if last[0] != b'\n' {
            line.insert(0, '\n');
        }
    }
    f.write_all(line.as_bytes())?;
    f.sync_data()?;
    Ok(())
}

/// The keys finished in the journal.
pub fn done_keys(rows: &[Row]) -> HashSet<String> {
    rows.iter().map(|r| r.key.clone()).collect()
}

fn one_bounce() -> String {
    use crate::settings::ParamType as _;
    crate::bounces::Bounces::ONE.text()
}

fn opt<T: ToString>(v: &Option<T>) -> String {
    v.as_ref().map(T::to_string).unwrap_or_default()
}

impl Row {
    /// The value of parameter `name` (`"vpls"`), if the row's method reads it.
    pub fn param(&self, name: &str) -> Option<&str> {
        self.params.get(name).map(String::as_str)
    }
}

/// The parameter names of all rows, in order of first appearance, but the
/// visibility's: a row's `visibility` column says it (`voxels 64`), in every
/// row, where theirs would be empty for the methods that read none.
pub fn param_names(rows: &[Row]) -> Vec<String> {
    use crate::visibility::VISIBILITY;
    use crate::voxel_grid::GRID;
    let mut names: Vec<String> = vec![];
    for r in rows {
        for n in r.params.keys() {
            if n == VISIBILITY.name || n == GRID.name {
                continue;
            }
            if !names.contains(n) {
                names.push(n.clone());
            }
        }
    }
    names
}

/// The pass names of all rows, in order of first appearance.
pub fn pass_names(rows: &[Row]) -> Vec<String> {
    let mut names: Vec<String> = vec![];
    for r in rows {
        for n in r.passes.keys() {
            if !names.contains(n) {
                names.push(n.clone());
            }
        }
    }
    names
}

/// `results.csv`: one line per row, a column per parameter (named as its
/// option) and per pass; empty cells where a value does not apply.
pub fn to_csv(rows: &[Row]) -> String {
    let params = param_names(rows);
    let passes = pass_names(rows);
    let mut out = String::from("scene,method,visibility,bounces,label,is_default");
    for p in &params {
        out += &format!(",{p}");
    }
    out += ",width,height,rsm,frames,indirect_ms,indirect_ms_min,total_ms,fragment_invocations,\
light_patch_evals,rel_rmse_indirect,rel_rmse_final,flip,flicker,flicker_second,flicker_final,\
flicker_pixel,gpu_memory_bytes,rel_rmse_truth,truth_spp,truth_noise,truth_left_out,truth_floor";
    for p in &passes {
        out += &format!(",{p}_ms");
    }
    out.push('\n');
    for r in rows {
        let mut cells = vec![
            r.scene.clone(),
            r.method.clone(),
            r.visibility.clone(),
            r.bounces.clone(),
            format!("\"{}\"", r.label),
            r.is_default.to_string(),
        ];
        cells.extend(
            params
                .iter()
                .map(|p| r.param(p).unwrap_or_default().to_string()),
        );
        cells.extend([
            r.width.to_string(),
            r.height.to_string(),
            r.rsm.to_string(),
            r.frames.to_string(),
            opt(&r.indirect_ms),
            opt(&r.indirect_ms_min),
            opt(&r.total_ms),
            opt(&r.fragment_invocations),
            opt(&r.light_patch_evals),
            r.rel_rmse_indirect.to_string(),
            r.rel_rmse_final.to_string(),
            r.flip.to_string(),
            opt(&r.flicker),
            opt(&r.flicker_second),
            opt(&r.flicker_final),
            opt(&r.flicker_pixel),
            opt(&r.gpu_memory_bytes),
            opt(&r.truth.rel_rmse_indirect),
            opt(&r.truth.spp),
            opt(&r.truth.noise),
            opt(&r.truth.left_out),
            opt(&r.truth.floor),
        ]);
        out += &cells.join(",");
        for p in &passes {
            out += &format!(",{}", opt(&r.passes.get(p)));
        }
        out.push('\n');
    }
    out
}

/// A filled-in row for tests.
#[cfg(test)]
pub(crate) mod tests_support {
    use super::*;

    pub(crate) fn row(key: &str) -> Row {
        Row {
            key: key.into(),
            scene: "s".into(),
            method: "hisr".into(),
            visibility: "none".into(),
            bounces: "1".into(),
            label: "tau 0.05, depth 6".into(),
            is_default: true,
            params: [("tau", "0.05"), ("max-depth", "6"), ("visibility", "none")]
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            width: 8,
            height: 8,
            rsm: 8,
            frames: 2,
            indirect_ms: Some(1.5),
            indirect_ms_min: Some(1.0),
            total_ms: Some(3.0),
            passes: [("gather".to_string(), 1.0)].into(),
            fragment_invocations: Some(10),
            light_patch_evals: None,
            rel_rmse_indirect: 0.1,
            rel_rmse_final: 0.05,
            flip: 0.02,
            flicker: Some(0.01),
            flicker_second: None,
            flicker_final: Some(0.005),
            flicker_pixel: Some(0.02),
            gpu_memory_bytes: Some(1024),
            truth: TruthErrors {
                rel_rmse_indirect: Some(0.12),
                ..Default::default()
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::tests_support::row;
    use super::*;

    #[test]
    fn the_journal_keeps_finished_rows_and_skips_a_torn_line() {
        let dir = std::env::temp_dir().join(format!("isr-journal-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(crate::bench::files::JOURNAL);
        let _ = std::fs::remove_file(&path);
        assert!(read_journal(&path).unwrap().rows.is_empty());
        append(&path, &row("a")).unwrap();
        append(&path, &row("b")).unwrap();
        // An interrupted write leaves half a line.
        std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap()
            .write_all(b"{\"key\": \"c\", \"sce")
            .unwrap();
        append(&path, &row("d")).unwrap();
        let journal = read_journal(&path).unwrap();
        assert_eq!(journal.rows, vec![row("a"), row("b"), row("d")]);
        assert_eq!(done_keys(&journal.rows).len(), 3);
        assert_eq!(journal.skipped, [(3, "cut off".to_string())]);
        // Cut inside a character, then bytes that are not UTF-8 at all.
        let mut r = row("é");
        r.scene = "café".into();
        append(&path, &r).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        let cut = bytes.windows(2).rposition(|w| w == "é".as_bytes()).unwrap() + 1;
        bytes.truncate(cut);
        assert!(std::str::from_utf8(&bytes).is_err());
        bytes.extend_from_slice(b"\n\xff\xfe\n{\"key\": 1}\n");
        std::fs::write(&path, &bytes).unwrap();
        append(&path, &row("e")).unwrap();
        let journal = read_journal(&path).unwrap();
        assert_eq!(journal.rows, vec![row("a"), row("b"), row("d"), row("e")]);
        let lines: Vec<usize> = journal.skipped.iter().map(|s| s.0).collect();
        assert_eq!(lines, [3, 5, 6, 7], "{:?}", journal.skipped);
        assert!(journal.skipped[1].1.starts_with("not valid UTF-8"));
        assert!(journal.skipped[3].1.starts_with("not a row"));
        let w = journal.warnings(&path);
        let skipped = format!("{} line 5 is skipped", crate::bench::files::JOURNAL);
        assert!(w[1].contains(&skipped), "{w:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn csv_has_a_column_per_pass_and_empty_cells_for_none() {
        let csv = to_csv(&[row("a")]);
        let lines: Vec<&str> = csv.lines().collect();
        assert!(lines[0].ends_with(",gather_ms"));
        // The visibility and the truth's bounces are columns of their own,
        // not parameters'.
        assert!(lines[0]
            .starts_with("scene,method,visibility,bounces,label,is_default,max-depth,tau,width,"));
        assert!(lines[1].contains(",hisr,none,1,\"tau 0.05, depth 6\",true,6,0.05,8,"));
        assert!(lines[1].ends_with(",1"));
    }
}
