//! The bench's bounces (docs/algorithm.md section 6.6, "Bounces"): `isr
//! bench --bounces N` measures every row against a path-traced truth of N
//! bounces (`inf`: every bounce), and every row, table and chart that shows
//! an error against the truth says which. The truth side of the axis, as
//! `visibility` is for indirect visibility: how a run's bounces key its rows
//! and its cached truth, and how they are labelled. The GPU methods render
//! one bounce whatever `--bounces` says (they do not read it yet), so a row
//! of N > 1 measures what the bounces they leave out cost too.

use super::rows::Row;
use super::Plan;
use crate::bounces::{Bounces, BOUNCES};
use crate::settings::{ParamType as _, RenderSettings};

/// The bounces of rows rendered with `s`, as rows and tables show them:
/// `1`, `3`, `inf` (what `--bounces` takes).
pub fn label(s: &RenderSettings) -> String {
    BOUNCES.get(s).text()
}

/// What a run's journal keys get for its bounces: nothing for one bounce,
/// so that a run without `--bounces` keeps the keys (and rows) of runs
/// before it; `|bounces N` else.
pub fn key_suffix(s: &RenderSettings) -> String {
    match BOUNCES.get(s) {
        Bounces::ONE => String::new(),
        b => format!("|bounces {}", b.text()),
    }
}

/// The file of frame `k`'s cached truth of `bounces` in its scene's truth
/// folder: `frame-K.exr` for one bounce (as before there were more, so that
/// a folder's cached truths keep serving), `frame-K-bounces-N.exr` else, so
/// that truths of different bounces live side by side.
pub fn truth_file(k: u32, bounces: Bounces) -> String {
    match bounces {
        Bounces::ONE => format!("frame-{k}.exr"),
        b => format!("frame-{k}-bounces-{}.exr", b.text()),
    }
}

/// "path-traced truth of 1 bounce": what a progress line or a title calls
/// the truth of `bounces`.
pub fn truth_words(bounces: Bounces) -> String {
    format!("path-traced truth of {}", bounces.words())
}

/// The run's warning when its truth has more bounces than the GPU methods
/// render: they do not read `--bounces` yet.
pub fn warning(s: &RenderSettings) -> Option<String> {
    let b = BOUNCES.get(s);
    (b != Bounces::ONE).then(|| {
        format!(
            "warning: --bounces {}: the truth is traced with {}, but the GPU methods render one \
             bounce (they do not read --bounces yet): their errors against the truth include \
             the light of the bounces they leave out",
            b.text(),
            b.words()
        )
    })
}

/// The bounces of `rows` (`Row::bounces`), in first appearance.
pub fn of_rows(rows: &[Row]) -> Vec<&str> {
    let mut out: Vec<&str> = vec![];
    for r in rows {
        if !out.contains(&r.bounces.as_str()) {
            out.push(&r.bounces);
        }
    }
    out
}

/// How the rows' truth is named in a chart's title or a report's line:
/// "the path-traced truth of 1 bounce", or with several bounces among the
/// rows, their list.
pub fn rows_truth_words(rows: &[Row]) -> String {
    let words: Vec<String> = of_rows(rows)
        .into_iter()
        .map(|b| match Bounces::parse(b) {
            Ok(b) => b.words(),
            Err(_) => format!("{b} bounces"),
        })
        .collect();
    match words.is_empty() {
        true => "the path-traced truth".into(),
        false => format!("the path-traced truth of {}", words.join(" and of ")),
    }
}

impl Plan {
    /// The bounces of this plan's truth (`--bounces`).
    pub fn bounces(&self) -> Bounces {
        BOUNCES.get(&self.base)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::BenchArgs;
    use crate::settings::params::Params;

    fn plan(bounces: Option<Bounces>) -> Plan {
        let mut params = Params::default();
        if let Some(b) = bounces {
            params = params.with(&BOUNCES, b);
        }
        BenchArgs {
            scenes: vec!["cornell".into()],
            methods: vec!["hisr".into()],
            params: crate::method_args::ParamArgsButVisibility(params),
            ..Default::default()
        }
        .plan()
        .unwrap()
    }

    #[test]
    fn one_bounce_keeps_the_keys_and_files_of_runs_before_and_others_are_apart() {
        let key = |p: &Plan| p.key("cornell", "hisr", "tau 0.2, depth 7");
        let (default, one) = (plan(None), plan(Some(Bounces::ONE)));
        assert_eq!(key(&default), key(&one));
        assert!(!key(&default).contains("bounces"), "{}", key(&default));
        assert_eq!(default.bounces(), Bounces::ONE);
        let two = plan(Some(Bounces::Count(2)));
        let inf = plan(Some(Bounces::Infinite));
        assert!(key(&two).ends_with("|bounces 2"), "{}", key(&two));
        assert!(key(&inf).ends_with("|bounces inf"), "{}", key(&inf));
        assert_eq!(inf.bounces(), Bounces::Infinite);
        // Every pass keeps the run's bounces.
        assert!(inf
            .passes()
            .iter()
            .all(|p| p.bounces() == Bounces::Infinite));
        assert_eq!(truth_file(3, Bounces::ONE), "frame-3.exr");
        assert_eq!(truth_file(3, Bounces::Count(2)), "frame-3-bounces-2.exr");
        assert_eq!(truth_file(0, Bounces::Infinite), "frame-0-bounces-inf.exr");
        assert!(warning(&default.base).is_none());
        let w = warning(&two.base).unwrap();
        assert!(
            w.contains("--bounces 2") && w.contains("render one bounce"),
            "{w}"
        );
    }

    #[test]
    fn rows_name_their_truths_bounces() {
        let mut a = crate::bench::rows::tests_support::row("a");
        let mut b = a.clone();
        assert_eq!(
            rows_truth_words(std::slice::from_ref(&a)),
            "the path-traced truth of 1 bounce"
        );
        a.bounces = "inf".into();
        b.bounces = "3".into();
        assert_eq!(
            rows_truth_words(&[a, b]),
            "the path-traced truth of every bounce and of 3 bounces"
        );
    }
}
