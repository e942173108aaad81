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
    /// Section 6.3 on the indirect image; `None` for a single frame.
    pub flicker: Option<f64>,
    pub flicker_second: Option<f64>,
    /// Section 6.3 on the final image.
    pub flicker_final: Option<f64>,
    /// GPU memory the method's resources take: the allocator's total with the
    /// method's renderer minus that with `--method none`.
    pub gpu_memory_bytes: Option<i64>,
}

/// The rows already finished in `path` (a missing file is an empty journal;
/// a line cut off by an interruption is skipped).
pub fn read_journal(path: &Path) -> Result<Vec<Row>> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(vec![]),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    Ok(text
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect())
}

/// Appends `row` as one line and flushes it to disk, so an interruption
/// keeps it.
pub fn append(path: &Path, row: &Row) -> Result<()> {
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .with_context(|| format!("cannot open {}", path.display()))?;
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

fn opt<T: ToString>(v: &Option<T>) -> String {
    v.as_ref().map(T::to_string).unwrap_or_default()
}

impl Row {
    /// The value of parameter `name` (`"vpls"`), if the row's method reads it.
    pub fn param(&self, name: &str) -> Option<&str> {
        self.params.get(name).map(String::as_str)
    }
}

/// The parameter names of all rows, in order of first appearance.
pub fn param_names(rows: &[Row]) -> Vec<String> {
    let mut names: Vec<String> = vec![];
    for r in rows {
        for n in r.params.keys() {
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
    let mut out = String::from("scene,method,label,is_default");
    for p in &params {
        out += &format!(",{p}");
    }
    out += ",width,height,rsm,frames,indirect_ms,indirect_ms_min,total_ms,fragment_invocations,\
light_patch_evals,rel_rmse_indirect,rel_rmse_final,flip,flicker,flicker_second,flicker_final,\
gpu_memory_bytes";
    for p in &passes {
        out += &format!(",{p}_ms");
    }
    out.push('\n');
    for r in rows {
        let mut cells = vec![
            r.scene.clone(),
            r.method.clone(),
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
            opt(&r.gpu_memory_bytes),
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
            label: "tau 0.05, depth 6".into(),
            is_default: true,
            params: [("tau", "0.05"), ("max-depth", "6")]
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
            gpu_memory_bytes: Some(1024),
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
        let path = dir.join("rows.jsonl");
        let _ = std::fs::remove_file(&path);
        assert!(read_journal(&path).unwrap().is_empty());
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
        let rows = read_journal(&path).unwrap();
        assert_eq!(rows, vec![row("a"), row("b"), row("d")]);
        assert_eq!(done_keys(&rows).len(), 3);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn csv_has_a_column_per_pass_and_empty_cells_for_none() {
        let csv = to_csv(&[row("a")]);
        let lines: Vec<&str> = csv.lines().collect();
        assert!(lines[0].ends_with(",gather_ms"));
        assert!(lines[0].starts_with("scene,method,label,is_default,max-depth,tau,width,"));
        assert!(lines[1].contains(",hisr,\"tau 0.05, depth 6\",true,6,0.05,8,"));
        assert!(lines[1].ends_with(",1"));
    }
}
