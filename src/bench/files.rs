//! The names of what a bench run writes into its folder, spelled once: the
//! writers, the checks before a run, the messages and the tests all read
//! them here, so that a renamed or added output cannot leave one of them
//! behind; and the one reader of a cached truth's EXR layers.

use std::path::{Path, PathBuf};

/// The journal: one row per line as it finishes, what a run resumes from.
pub const JOURNAL: &str = "rows.jsonl";
/// Every row with the run's facts and ratios.
pub const RESULTS_JSON: &str = "results.json";
/// One line per row, a column per parameter.
pub const RESULTS_CSV: &str = "results.csv";
/// Every method's image beside the reference's, with its FLIP map.
pub const GALLERY: &str = "gallery.png";
/// The run's facts, charts, tables and ratios.
pub const REPORT: &str = "report.md";
/// The folder of the gallery's images, one folder per scene in it.
pub const IMAGES: &str = "images";
/// The folder of the cached path-traced truth, one folder per scene in it.
pub const TRUTH: &str = "truth";

/// The charts, each written as `STEM.svg` and `STEM.png`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chart {
    SpeedVsError,
    SpeedVsTruth,
    Flicker,
    Passes,
}

impl Chart {
    /// In the order they are written and shown in `report.md`.
    pub const ALL: [Chart; 4] = [
        Chart::SpeedVsError,
        Chart::SpeedVsTruth,
        Chart::Flicker,
        Chart::Passes,
    ];

    /// The file name without its extension.
    pub fn stem(self) -> &'static str {
        match self {
            Chart::SpeedVsError => "speed_vs_error",
            Chart::SpeedVsTruth => "speed_vs_truth",
            Chart::Flicker => "flicker",
            Chart::Passes => "passes",
        }
    }

    /// The SVG's file name (the one `report.md` shows).
    pub fn svg(self) -> String {
        format!("{}.svg", self.stem())
    }

    /// The PNG's file name.
    pub fn png(self) -> String {
        format!("{}.png", self.stem())
    }
}

/// Every file `report::write_all` writes into the run's folder, in the
/// order it writes them.
pub fn written() -> Vec<String> {
    let mut files = vec![RESULTS_JSON.to_string(), RESULTS_CSV.to_string()];
    for c in Chart::ALL {
        files.extend([c.svg(), c.png()]);
    }
    files.extend([GALLERY.to_string(), REPORT.to_string()]);
    files
}

/// What the end of a run says it wrote: "results.json, results.csv,
/// charts, gallery.png and report.md".
pub fn summary() -> String {
    format!("{RESULTS_JSON}, {RESULTS_CSV}, charts, {GALLERY} and {REPORT}")
}

/// The folder of scene `scene`'s gallery images in run folder `dir`.
pub fn images_dir(dir: &Path, scene: &str) -> PathBuf {
    dir.join(IMAGES).join(scene)
}

/// The folder of scene `scene`'s cached truth in run folder `dir`.
pub fn truth_dir(dir: &Path, scene: &str) -> PathBuf {
    dir.join(TRUTH).join(scene)
}

/// The gallery image of `method` (or `reference`) in the pass whose images
/// take `suffix` (`Plan::image_suffix`): `hisr.png`, `hisr-voxels.png`.
pub fn image(method: &str, suffix: &str) -> String {
    format!("{method}{suffix}.png")
}

/// The FLIP map beside [`image`]: `hisr-error.png`, `hisr-voxels-error.png`.
pub fn error_map(method: &str, suffix: &str) -> String {
    format!("{method}{suffix}-error.png")
}

/// The layer `name` of the EXR `image` as RGBA pixels (alpha 1): how the
/// truth cache and the bounce examples read a truth back.
pub fn exr_layer(
    image: &exr::prelude::FlatImage,
    name: &str,
    pixels: usize,
) -> Option<Vec<[f32; 4]>> {
    use exr::prelude::FlatSamples;
    let layer = image.layer_data.iter().find(|l| {
        l.attributes
            .layer_name
            .as_ref()
            .map(|n| n.to_string())
            .as_deref()
            == Some(name)
    })?;
    let channel = |c: &str| {
        layer
            .channel_data
            .list
            .iter()
            .find(|ch| ch.name.to_string() == c)
            .and_then(|ch| match &ch.sample_data {
                FlatSamples::F32(v) if v.len() == pixels => Some(v.clone()),
                _ => None,
            })
    };
    let (r, g, b) = (channel("R")?, channel("G")?, channel("B")?);
    Some((0..pixels).map(|k| [r[k], g[k], b[k], 1.0]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_written_file_is_named_once() {
        let files = written();
        for (i, f) in files.iter().enumerate() {
            assert!(!files[i + 1..].contains(f), "{f} twice");
            assert_ne!(f, JOURNAL);
        }
        assert_eq!(files.len(), 4 + 2 * Chart::ALL.len());
    }
}
