//! Every registered method parameter as a command-line option: `--NAME
//! VALUE`, one per parameter of any method (`methods::all_params`), with its
//! help, default and range in `--help`. `isr render`, `isr view` and `isr bench` flatten
//! [`ParamArgs`] into their arguments (`#[command(flatten)]`), so a
//! parameter declared in its method's module reaches every command without
//! a line of CLI code. Values are parsed for their type here and checked
//! against their ranges with the other settings (`methods::check`).

use crate::methods::{all_params, params_of, REGISTRY};
use crate::passes::rsm_tree;
use crate::settings::params::AnyParam;
use crate::settings::{Params, Value};
use crate::{multires, regular_vpls, visibility};

/// The parameters given on the command line (the others keep their defaults).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamArgs(pub Params);

/// `--help`'s text for `p`: its help, default, range and the methods that read it.
fn help_text(p: &dyn AnyParam) -> String {
    let readers = readers(p);
    let range = match *p.range() {
        r if r == crate::settings::Range::ANY => String::new(),
        r => format!("; {}", r.describe()),
    };
    // A run parameter no method reads yet says who does in its help.
    let readers = match readers.is_empty() {
        true => String::new(),
        false => format!(" [methods: {}]", readers.join(", ")),
    };
    format!(
        "{}. [default: {}{range}]{readers}",
        p.help(),
        p.default_text()
    )
}

/// The methods that read `p`, in registry order.
fn readers(p: &dyn AnyParam) -> Vec<&'static str> {
    REGISTRY
        .iter()
        .filter(|d| params_of(**d).any(|q| q.name() == p.name()))
        .map(|d| d.key().name())
        .collect()
}

/// The heading `p` is listed under in `--help`: the shared layer that
/// declares it (with the methods that read it), or the method whose own
/// parameter it is.
fn heading(p: &dyn AnyParam) -> String {
    let has = |list: &[&dyn AnyParam]| list.iter().any(|q| q.name() == p.name());
    let shared = if has(visibility::PARAMS) {
        Some("Indirect visibility")
    } else if has(multires::PARAMS) {
        Some("Eye-space hierarchy")
    } else if has(regular_vpls::PARAMS) {
        Some("Regular VPLs")
    } else if has(rsm_tree::PARAMS) {
        Some("RSM quadtree")
    } else if p.name() == crate::bounces::BOUNCES.name || p.name() == crate::bounce::FEEDBACK.name {
        Some("Bounces")
    } else {
        None
    };
    let readers = readers(p);
    match shared {
        Some(what) => format!("{what} ({})", readers.join(", ")),
        None => format!("--method {}", readers.first().copied().unwrap_or("?")),
    }
}

/// Whether `-h` shows `p`: a method's main knob, the visibility choice or
/// the bounces; `--help` shows every parameter, the ablation knobs too.
pub fn in_short_help(p: &dyn AnyParam) -> bool {
    p.name() == visibility::VISIBILITY.name
        || p.name() == crate::bounces::BOUNCES.name
        || REGISTRY
            .iter()
            .any(|d| d.main_param().is_some_and(|q| q.name() == p.name()))
}

/// [`ParamArgs`] but for `--visibility`: `isr bench` takes a list there
/// (its visibility axis, `bench::visibility`), where the parameter is one value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamArgsButVisibility(pub Params);

/// Both kinds are clap arguments, one option per parameter but those named.
macro_rules! param_args {
    ($t:ty, $except:expr) => {
        impl clap::FromArgMatches for $t {
            fn from_arg_matches(m: &clap::ArgMatches) -> Result<Self, clap::Error> {
                let mut args = Self::default();
                args.update_from_arg_matches(m)?;
                Ok(args)
            }

            fn update_from_arg_matches(&mut self, m: &clap::ArgMatches) -> Result<(), clap::Error> {
                self.0 .0.extend(read(m, $except).0);
                Ok(())
            }
        }

        impl clap::Args for $t {
            fn augment_args(cmd: clap::Command) -> clap::Command {
                augment(cmd, $except)
            }

            fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
                augment(cmd, $except)
            }
        }
    };
}

param_args!(ParamArgs, &[]);
param_args!(
    ParamArgsButVisibility,
    &[crate::visibility::VISIBILITY.name]
);

/// The values given in `m` of every parameter but those in `except`.
fn read(m: &clap::ArgMatches, except: &[&str]) -> Params {
    let mut params = Params::default();
    for p in all_params() {
        if except.contains(&p.name()) {
            continue;
        }
        if let Some(v) = m.get_one::<Value>(p.name()) {
            params.insert(p.name(), *v);
        }
    }
    params
}

/// `cmd` with an option per parameter but those in `except`.
fn augment(mut cmd: clap::Command, except: &[&str]) -> clap::Command {
    for p in all_params() {
        if except.contains(&p.name()) {
            continue;
        }
        cmd = cmd.arg(
            clap::Arg::new(p.name())
                .long(p.name())
                .value_name(p.value_name())
                .help(format!("{} [default: {}]", p.help(), p.default_text()))
                .long_help(help_text(p))
                .help_heading(heading(p))
                .hide_short_help(!in_short_help(p))
                .allow_negative_numbers(true)
                .value_parser(move |text: &str| p.parse(text)),
        );
    }
    cmd
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{Args as _, FromArgMatches as _};

    fn parse(args: &[&str]) -> Result<ParamArgs, clap::Error> {
        let cmd = ParamArgs::augment_args(clap::Command::new("t").no_binary_name(true));
        ParamArgs::from_arg_matches(&cmd.try_get_matches_from(args)?)
    }

    #[test]
    fn every_parameter_is_an_option_and_only_given_ones_are_kept() {
        let p = parse(&["--tau", "0.2", "--stencil", "off", "--upsample", "nearest"]).unwrap();
        assert_eq!(p.0.get("tau"), Some(Value::Real(0.2)));
        assert_eq!(p.0.get("stencil"), Some(Value::Switch(false)));
        assert_eq!(p.0.get("upsample"), Some(Value::Choice(1)));
        assert_eq!(p.0 .0.len(), 3);
        // Out of range parses (the range is checked with the settings); a
        // wrong type does not.
        assert!(parse(&["--tau", "-1"]).is_ok());
        assert!(parse(&["--vpls", "many"]).is_err());
        assert!(parse(&["--upsample", "cubic"]).is_err());
        let names: Vec<&str> = all_params().iter().map(|p| p.name()).collect();
        for n in [
            "vpls",
            "tau",
            "levels",
            "isr-base",
            "splat-threshold",
            "reference-chunk",
        ] {
            assert!(names.contains(&n), "{n}");
        }
    }
}
