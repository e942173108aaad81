//! With `isr bench --publish ROOT`: the run's report as
//! `ROOT/docs/results.md` (its charts, gallery and rows in
//! `ROOT/docs/results/`) and its headline tables (`headline`) in
//! `ROOT/README.md` between [`BEGIN`] and [`END`], so that every figure the
//! README and docs/results.md show comes from the command named beside it.

use super::files::{self, Chart};
use super::headline::headline;
pub use super::headline::{block, BEGIN, END};
use super::{Outcome, Plan};
use anyhow::{bail, Context as _, Result};
use std::path::Path;

/// Writes the run's report and outputs into `root`'s docs (docs/results.md,
/// docs/results/) and its headline block into `root`'s README.md.
pub fn publish(plan: &Plan, o: &Outcome, root: &Path) -> Result<()> {
    let readme_path = root.join("README.md");
    let readme = std::fs::read_to_string(&readme_path)
        .with_context(|| format!("--publish {}: reading its README.md", root.display()))?;
    let Some(old) = block(&readme) else {
        bail!(
            "--publish {}: README.md has no block between {BEGIN} and {END} for the headline tables",
            root.display()
        );
    };
    let docs = root.join("docs");
    let dir = docs.join("results");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let out = &plan.out_dir;
    let mut copied: Vec<String> = vec![
        files::RESULTS_CSV.into(),
        files::RESULTS_JSON.into(),
        files::GALLERY.into(),
    ];
    for c in Chart::ALL {
        copied.extend([c.svg(), c.png()]);
    }
    for f in &copied {
        std::fs::copy(out.join(f), dir.join(f))
            .with_context(|| format!("copying {} into {}", out.join(f).display(), dir.display()))?;
    }
    let report = super::report::markdown(plan, o, &super::ratios::ratios(&o.rows), "results/");
    crate::output::write_text(&docs.join("results.md"), &report)?;
    let headline = headline(plan, o);
    let new = readme.replacen(old, headline.trim_end(), 1);
    crate::output::write_text(&readme_path, &new)?;
    println!(
        "published docs/results.md, docs/results/ and README.md's headline tables into {}",
        root.display()
    );
    Ok(())
}
