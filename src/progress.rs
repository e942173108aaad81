//! The one progress bar of every long run (`isr render` over several frames
//! or the reference's chunks, `--sequence`, `pathtrace`, `isr bench`):
//! indicatif's, with the time left. indicatif draws it on stderr only when
//! stderr is a terminal, so a log gets no carriage-return redraws.

/// A bar of `len` units (`unit`: "frames", "rows"), with a message after it.
pub fn bar(len: u64, unit: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template(&format!(
            "[{{elapsed_precise}}] {{bar:30}} {{pos}}/{{len}} {unit}, {{eta}} left: {{msg}}"
        ))
        .expect("the progress template is valid"),
    );
    bar
}
