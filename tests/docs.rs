//! Docs that cannot drift from the code (no GPU, milliseconds): every option
//! of `isr render`, `view` and `bench` is in docs/guide.md and every option
//! guide.md names exists; README.md's headline tables are docs/results.md's
//! (both written by `isr bench --publish`); the constants docs/algorithm.md
//! quotes hold the values the shaders give them, and it quotes no
//! specialization constant's value (a shader switch is named, not numbered).

use std::collections::BTreeSet;
use std::path::Path;

fn read(path: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The long options of `isr SUBCOMMAND`.
fn options(subcommand: &str) -> BTreeSet<String> {
    let cli = isr::cli::command();
    let sub = cli
        .get_subcommands()
        .find(|c| c.get_name() == subcommand)
        .unwrap_or_else(|| panic!("no subcommand {subcommand}"));
    sub.get_arguments()
        .filter_map(|a| a.get_long())
        .map(|l| format!("--{l}"))
        // clap's own (every command has it).
        .chain(["--help".to_string()])
        .collect()
}

/// Every `--name` in `text` (a word of lower-case letters, digits and
/// hyphens after two hyphens, not inside a longer word).
fn named_options(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let bytes = text.as_bytes();
    for (i, _) in text.match_indices("--") {
        if i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'-') {
            continue;
        }
        let name: String = text[i + 2..]
            .chars()
            .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '-')
            .collect();
        let name = name.trim_end_matches('-');
        if name.len() > 1 {
            out.insert(format!("--{name}"));
        }
    }
    out
}

#[test]
fn every_option_is_in_the_guide_and_every_option_it_names_exists() {
    let guide = read("docs/guide.md");
    let named = named_options(&guide);
    let mut all = BTreeSet::new();
    let mut missing = vec![];
    for sub in ["render", "view", "bench"] {
        for o in options(sub) {
            if !named.contains(&o) {
                missing.push(format!("isr {sub} {o}"));
            }
            all.insert(o);
        }
    }
    assert!(
        missing.is_empty(),
        "options docs/guide.md does not name:\n{}",
        missing.join("\n")
    );
    // Flags of other programs the guide shows in commands.
    let others = [
        "--release",
        "--bench",
        "--example",
        "--validation",
        "--all-targets",
        "--test",
        "--nocapture",
        "--no-fail-fast",
        "--examples",
    ];
    let unknown: Vec<&String> = named
        .iter()
        .filter(|o| !all.contains(*o) && !others.contains(&o.as_str()))
        .collect();
    assert!(
        unknown.is_empty(),
        "docs/guide.md names options isr does not have: {unknown:?}"
    );
}

#[test]
fn the_readme_shows_the_headline_tables_of_the_published_results() {
    let readme = read("README.md");
    let results = read("docs/results.md");
    let a = isr::bench::publish::block(&readme).expect("README.md's headline block");
    let b = isr::bench::publish::block(&results).expect("docs/results.md's headline block");
    assert_eq!(
        a, b,
        "README.md's headline tables are not docs/results.md's: publish both with \
         `isr bench --publish .`"
    );
}

/// Every row of docs/algorithm.md's constants table that gives a shader
/// constant a plain number holds the shader's value.
#[test]
fn the_constants_the_reference_quotes_are_the_shaders() {
    let doc = read("docs/algorithm.md");
    let table = doc
        .split("## Appendix B")
        .nth(1)
        .expect("docs/algorithm.md has an Appendix B");
    let backticked = |cell: &str| -> Vec<String> {
        cell.split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_string)
            .collect()
    };
    let mut checked = 0;
    for line in table.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (names, values, wheres) = (backticked(cells[1]), cells[2], backticked(cells[3]));
        let Some(shader) = wheres.iter().find(|w| {
            [".glsl", ".frag", ".comp", ".vert"]
                .iter()
                .any(|e| w.ends_with(e))
        }) else {
            continue;
        };
        let source = read(&format!("shaders/{shader}"));
        for (name, value) in names.iter().zip(values.split(',')) {
            let Ok(quoted) = value.split_whitespace().next().unwrap_or("").parse::<f64>() else {
                continue;
            };
            let line = source
                .lines()
                .find(|l| l.starts_with("const ") && l.contains(&format!(" {name} = ")))
                .unwrap_or_else(|| panic!("shaders/{shader} defines no constant {name}"));
            let value: f64 = line
                .split('=')
                .nth(1)
                .unwrap()
                .split(';')
                .next()
                .unwrap()
                .trim()
                .trim_end_matches('u')
                .parse()
                .unwrap();
            assert_eq!(
                value, quoted,
                "{name}: shaders/{shader} says {value}, the doc {quoted}"
            );
            checked += 1;
        }
    }
    assert!(
        checked >= 5,
        "only {checked} constants checked: did the table change?"
    );
}

#[test]
fn the_reference_names_shader_switches_rather_than_quoting_their_values() {
    let doc = read("docs/algorithm.md");
    let mut quoted = vec![];
    for shader in isr::vk::pipeline::shader_names() {
        let words = isr::vk::pipeline::spirv(shader).unwrap();
        for c in isr::vk::reflect::spec_constants(&words).unwrap() {
            for form in [format!("{} = ", c.name), format!("{}=", c.name)] {
                for (i, _) in doc.match_indices(&form) {
                    let after = &doc[i + form.len()..];
                    if after.starts_with(|ch: char| ch.is_ascii_digit()) {
                        quoted.push(format!("{}{}", form, &after[..after.len().min(8)]));
                    }
                }
            }
        }
    }
    assert!(
        quoted.is_empty(),
        "docs/algorithm.md quotes the values of shader switches (name them instead): {quoted:?}"
    );
}

/// The defaults `isr` ships are the subject's best balance in the published
/// run (one definition, `bench::headline::best_balance`): `isr render` with
/// no option renders the setting docs/results.md names.
#[test]
fn the_default_is_the_best_balance_of_the_published_run() {
    let json: serde_json::Value =
        serde_json::from_str(&read("docs/results/results.json")).expect("results.json");
    let rows: Vec<isr::bench::rows::Row> =
        serde_json::from_value(json["rows"].clone()).expect("the published rows");
    let subject_key = || isr::methods::SUBJECT;
    let subject = isr::methods::SUBJECT.name();
    let best = isr::bench::headline::best_balance(&rows, subject).expect("a best balance");
    let row = rows
        .iter()
        .find(|r| r.method == subject && r.label == best.label && r.visibility == best.visibility)
        .unwrap();
    let defaults = isr::settings::RenderSettings::default();
    assert_eq!(
        defaults.method,
        isr::methods::SUBJECT,
        "the default method is the subject"
    );
    // The knobs the rule chooses: the method's main one and the visibility
    // (others, such as the levels, derive from the image's size, which the
    // bench's differs from a render's).
    let descriptor = isr::methods::find(subject_key()).expect("the subject is registered");
    let main = descriptor
        .main_param()
        .expect("the subject has a main knob");
    let visibility: &dyn isr::settings::params::AnyParam = &isr::visibility::VISIBILITY;
    for p in [main, visibility] {
        let ours = p.text_in(&defaults);
        let published = row.params.get(p.name()).expect("the row names the knob");
        assert_eq!(
            &ours,
            published,
            "--{}: the default is {ours}, the best balance of docs/results.md {published} ({} {})",
            p.name(),
            best.label,
            best.visibility
        );
    }
}

/// The default bounces are the subject's best balance on the published
/// run's bounces axis (`bench::bounce_axis::default_bounces`, the same rule
/// as the other defaults, against the truth of every bounce): `isr render`
/// with no option renders the bounces docs/results.md names.
#[test]
fn the_default_bounces_are_the_best_balance_of_the_published_bounces_axis() {
    use isr::settings::params::AnyParam as _;
    let json: serde_json::Value =
        serde_json::from_str(&read("docs/results/results.json")).expect("results.json");
    let rows: Vec<isr::bench::rows::Row> = serde_json::from_value(json["bounce_axis"].clone())
        .expect("the published run's bounces axis (`bounce_axis` in results.json)");
    let (best, _) = isr::bench::bounce_axis::default_bounces(&rows);
    let best = best.expect("a best balance of the subject's bounces");
    let ours = isr::bounces::BOUNCES.text_in(&isr::settings::RenderSettings::default());
    assert_eq!(
        ours, best.label,
        "--bounces: the default is {ours}, the best balance of docs/results.md's bounces axis {} \
         ({:.2}x the lowest error against the truth of every bounce)",
        best.label, best.relative_error
    );
}
