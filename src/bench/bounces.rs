//! The bench's bounces (docs/algorithm.md section 6.6, "Bounces"): `isr
//! bench --bounces N` measures every row against a path-traced truth of N
//! bounces (`inf`: every bounce), and every row, table and chart that shows
//! an error against the truth says which. The truth side of the axis, as
//! `visibility` is for indirect visibility: how a run's bounces key its rows
//! and its cached truth, and how they are labelled. The methods that render
//! bounces (`Descriptor::renders_bounces`: the gathering methods, the
//! splats, the reference) render N of them through the shared bounce passes
//! (`bounce`); the others (`none`, `lpv`) render one, so their rows of
//! N > 1 measure what the bounces they leave out cost too.

use super::rows::Row;
use super::Plan;
use crate::bounces::{Bounces, BOUNCES};
use crate::settings::{Method, ParamType as _, RenderSettings};

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

/// The run's warning when its truth has more bounces than some of its
/// `methods` render: those that do not render bounces (`none`, `lpv`).
pub fn warning(s: &RenderSettings, methods: &[Method]) -> Option<String> {
    let b = BOUNCES.get(s);
    let one: Vec<&str> = methods
        .iter()
        .filter_map(|&m| crate::methods::find(m).ok())
        .filter(|d| !d.renders_bounces())
        .map(|d| d.key().name())
        .collect();
    (b != Bounces::ONE && !one.is_empty()).then(|| {
        format!(
            "warning: --bounces {}: the truth is traced with {}, but {} render{} one bounce: \
             {} errors against the truth include the light of the bounces {} leave{} out",
            b.text(),
            b.words(),
            one.join(", "),
            if one.len() == 1 { "s" } else { "" },
            if one.len() == 1 { "its" } else { "their" },
            if one.len() == 1 { "it" } else { "they" },
            if one.len() == 1 { "s" } else { "" },
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
        let (none, hisr) = (crate::methods::DIRECT_ONLY, crate::methods::SUBJECT);
        assert!(warning(&default.base, &[none]).is_none());
        // A method that renders bounces is not warned of; one that does not is.
        assert!(warning(&two.base, &[hisr]).is_none());
        let w = warning(&two.base, &[hisr, none]).unwrap();
        assert!(
            w.contains("--bounces 2") && w.contains("none renders one bounce"),
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
