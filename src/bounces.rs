//! How many bounces of indirect light a run computes (docs/algorithm.md
//! section 5.4, "Bounces"): `--bounces N`, a count from 1 to 8, or `inf`
//! for the whole series. A parameter of the run, not of one method: the
//! path tracer reads it, and so the bench's truth (`bench::truth`), and the
//! GPU methods that `renders_bounces` (the gathering methods, the splats,
//! the reference) add bounces 2..N through the shared bounce passes
//! (`bounce`, docs/algorithm.md section 5.9); for the others (`none`,
//! `lpv`) it is a parameter with no effect (the CLI warns of it as of any
//! other).
//!
//! The path tracer keeps the light of bounces 1, 2, 3 and "4 and more" in
//! separate layers ([`LAYERS`]), so that one trace gives every smaller N:
//! the image of N bounces is the sum of the first N layers.

use crate::settings::params::{DefaultValue, Param, ParamType, Range, Value};

/// The most bounces a count may ask for (`inf` asks for all of them).
pub const MAX_COUNT: u32 = 8;

/// The bounces of indirect light a run computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bounces {
    /// Bounces 1 to N (N from 1 to [`MAX_COUNT`]; others fail the range check).
    Count(u32),
    /// Every bounce: paths run until Russian roulette ends them.
    Infinite,
}

impl Bounces {
    /// Today's default: the first bounce only.
    pub const ONE: Bounces = Bounces::Count(1);

    /// The last bounce traced; `None` for every bounce.
    pub fn last(self) -> Option<u32> {
        match self {
            Bounces::Count(n) => Some(n),
            Bounces::Infinite => None,
        }
    }

    /// How many of the path tracer's layers ([`LAYERS`]) hold light: one
    /// per bounce up to 3, and the fourth (bounces 4 to N) from N = 4 on.
    pub fn layers(self) -> usize {
        match self {
            Bounces::Count(n) => (n as usize).clamp(1, LAYERS.len()),
            Bounces::Infinite => LAYERS.len(),
        }
    }

    /// "1 bounce", "3 bounces", "every bounce": for titles and reports.
    pub fn words(self) -> String {
        match self {
            Bounces::Count(1) => "1 bounce".into(),
            Bounces::Count(n) => format!("{n} bounces"),
            Bounces::Infinite => "every bounce".into(),
        }
    }
}

/// The EXR layers of the light of each bounce, as the path tracer keeps it
/// (irradiance, as `indirect`): bounces 1, 2, 3, and 4 to N (every bounce
/// from the fourth with `inf`). A run writes the first [`Bounces::layers`].
pub const LAYERS: [&str; 4] = [
    "indirect.bounce1",
    "indirect.bounce2",
    "indirect.bounce3",
    "indirect.bounce4plus",
];

/// A count is a `Value::Count`; `inf` is the count no range holds, so that
/// it can never be mistaken for a number of bounces.
const INFINITE: u64 = u64::MAX;

impl ParamType for Bounces {
    fn to_value(self) -> Value {
        match self {
            Bounces::Count(n) => Value::Count(n as u64),
            Bounces::Infinite => Value::Count(INFINITE),
        }
    }
    fn from_value(v: Value) -> Option<Self> {
        match v {
            Value::Count(INFINITE) => Some(Bounces::Infinite),
            Value::Count(n) => u32::try_from(n).ok().map(Bounces::Count),
            _ => None,
        }
    }
    fn text(self) -> String {
        match self {
            Bounces::Count(n) => n.to_string(),
            Bounces::Infinite => "inf".into(),
        }
    }
    fn parse(text: &str) -> Result<Self, String> {
        if text == "inf" {
            return Ok(Bounces::Infinite);
        }
        text.parse()
            .map(Bounces::Count)
            .map_err(|_| format!("'{text}' is neither a whole number of bounces nor inf"))
    }
    /// `inf` has no number: the range holds the counts only.
    fn number(self) -> Option<f64> {
        self.last().map(f64::from)
    }
    fn value_name() -> String {
        "N|inf".into()
    }
}

pub const BOUNCES: Param<Bounces> = Param {
    name: "bounces",
    help: "Bounces of indirect light: a count, or inf for every bounce (paths end by Russian \
           roulette). --method pathtrace reads it, the truth of isr bench, and every gathering \
           method (bounces 2..N through the voxel grid's cells; inf: until a bounce adds under \
           1%)",
    // Every bounce: the cheapest setting within 1.25x of the lowest error
    // against the truth of every bounce (docs/results.md, "Bounces"; a test
    // holds it to the published run).
    default: DefaultValue::Fixed(Bounces::Infinite),
    range: Range::closed(1.0, MAX_COUNT as f64),
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::params::AnyParam;
    use crate::settings::RenderSettings;

    #[test]
    fn counts_and_inf_parse_round_trip_and_are_checked() {
        assert_eq!(BOUNCES.parse("inf"), Ok(Value::Count(INFINITE)));
        assert_eq!(BOUNCES.parse("3"), Ok(Value::Count(3)));
        assert!(BOUNCES.parse("infinity").is_err() && BOUNCES.parse("-1").is_err());
        for b in [Bounces::ONE, Bounces::Count(8), Bounces::Infinite] {
            assert_eq!(Bounces::parse(&b.text()), Ok(b));
            assert_eq!(Bounces::from_value(b.to_value()), Some(b));
        }
        let mut s = RenderSettings::DEFAULT;
        assert_eq!(BOUNCES.get(&s), Bounces::Infinite);
        assert!(BOUNCES.check(&s).is_ok());
        assert_eq!(BOUNCES.text_in(&s), "inf");
        for bad in [0, MAX_COUNT + 1] {
            BOUNCES.set(&mut s, Bounces::Count(bad));
            let e = BOUNCES.check(&s).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("--bounces {bad}: must be within [1, 8]")),
                "{e}"
            );
        }
        assert_eq!(BOUNCES.value_name(), "N|inf");
    }

    #[test]
    fn the_image_of_n_bounces_sums_the_first_n_layers() {
        let layers = |b| Bounces::layers(b);
        assert_eq!(layers(Bounces::ONE), 1);
        assert_eq!(layers(Bounces::Count(3)), 3);
        assert_eq!(layers(Bounces::Count(7)), 4);
        assert_eq!(layers(Bounces::Infinite), 4);
    }
}
