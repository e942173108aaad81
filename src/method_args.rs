//! Every registered method parameter as a command-line option: `--NAME
//! VALUE`, one per parameter of any method (`methods::all_params`), with its
//! help, default and range in `--help`. `isr render`, `isr view` and `isr bench` flatten
//! [`ParamArgs`] into their arguments (`#[command(flatten)]`), so a
//! parameter declared in its method's module reaches every command without
//! a line of CLI code. Values are parsed for their type here and checked
//! against their ranges with the other settings (`methods::check`).

use crate::methods::{all_params, params_of, REGISTRY};
use crate::settings::params::AnyParam;
use crate::settings::{Params, Value};

/// The parameters given on the command line (the others keep their defaults).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamArgs(pub Params);

/// `--help`'s text for `p`: its help, default, range and the methods that read it.
fn help_text(p: &dyn AnyParam) -> String {
    let readers: Vec<&str> = REGISTRY
        .iter()
        .filter(|d| params_of(**d).any(|q| q.name() == p.name()))
        .map(|d| d.key().name())
        .collect();
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
                .help(help_text(p))
                .help_heading("Method parameters")
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
