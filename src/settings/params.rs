//! Named parameters with one valid range each. A method (or a shared pass)
//! declares its parameters as constants in its own module
//! (`pub const TAU: Param<f32> = ...`); the registry lists them per method,
//! the CLI makes one `--NAME` option of each, and the checks, the viewer's
//! keys and the bench's sweeps all read the range declared here. Values are
//! kept in `RenderSettings::params` by name, only where they differ from the
//! default, so the defaults live in one place: the declaration.

use super::RenderSettings;
use anyhow::{bail, Result};
use std::collections::BTreeMap;

/// A parameter's value as stored in `RenderSettings::params`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Real(f32),
    Count(u64),
    Switch(bool),
    /// An index into the parameter's choices.
    Choice(usize),
}

/// One end of a range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    None,
    Closed(f64),
    Open(f64),
}

/// Where a numeric parameter is valid: between two bounds and, for counts,
/// optionally only at powers of 2 or 4.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub min: Bound,
    pub max: Bound,
    /// Counts only: the value must be a power of this (2 or 4).
    pub power_of: Option<u32>,
}

impl Range {
    /// Any finite value.
    pub const ANY: Range = Range {
        min: Bound::None,
        max: Bound::None,
        power_of: None,
    };

    pub const fn closed(min: f64, max: f64) -> Self {
        Range {
            min: Bound::Closed(min),
            max: Bound::Closed(max),
            power_of: None,
        }
    }

    pub const fn open(min: f64, max: f64) -> Self {
        Range {
            min: Bound::Open(min),
            max: Bound::Open(max),
            power_of: None,
        }
    }

    pub const fn at_least(min: f64) -> Self {
        Range {
            min: Bound::Closed(min),
            max: Bound::None,
            power_of: None,
        }
    }

    /// Powers of `base` from `min` to `max`.
    pub const fn powers_of(base: u32, min: f64, max: f64) -> Self {
        Range {
            min: Bound::Closed(min),
            max: Bound::Closed(max),
            power_of: Some(base),
        }
    }

    pub fn contains(&self, x: f64) -> bool {
        let above = match self.min {
            Bound::None => true,
            Bound::Closed(m) => x >= m,
            Bound::Open(m) => x > m,
        };
        let below = match self.max {
            Bound::None => true,
            Bound::Closed(m) => x <= m,
            Bound::Open(m) => x < m,
        };
        let power = match self.power_of {
            None => true,
            Some(b) => is_power_of(x, b),
        };
        x.is_finite() && above && below && power
    }

    /// `x` moved into the range: a closed bound clamps to itself, an open
    /// bound to halfway between `from` (a value inside) and the bound, so
    /// that repeated steps toward it approach it without reaching it.
    pub fn clamp_from(&self, from: f64, x: f64) -> f64 {
        let x = match self.max {
            Bound::Closed(m) if x > m => m,
            Bound::Open(m) if x >= m => (from + m) / 2.0,
            _ => x,
        };
        match self.min {
            Bound::Closed(m) if x < m => m,
            Bound::Open(m) if x <= m => (from + m) / 2.0,
            _ => x,
        }
    }

    /// "within (0, 1)", "a power of 4 from 1 to 16777216", "at least 0".
    pub fn describe(&self) -> String {
        let num = |x: f64| format!("{x}");
        let bounds = match (self.min, self.max) {
            (Bound::None, Bound::None) => "any finite number".to_string(),
            (Bound::Closed(a), Bound::None) => format!("at least {}", num(a)),
            (Bound::Open(a), Bound::None) => format!("greater than {}", num(a)),
            (Bound::None, Bound::Closed(b)) => format!("at most {}", num(b)),
            (Bound::None, Bound::Open(b)) => format!("less than {}", num(b)),
            (lo, hi) => {
                let (l, a) = match lo {
                    Bound::Open(a) => ("(", a),
                    Bound::Closed(a) => ("[", a),
                    Bound::None => unreachable!(),
                };
                let (h, b) = match hi {
                    Bound::Open(b) => (")", b),
                    Bound::Closed(b) => ("]", b),
                    Bound::None => unreachable!(),
                };
                match self.power_of {
                    Some(_) => format!("from {} to {}", num(a), num(b)),
                    None => format!("within {l}{}, {}{h}", num(a), num(b)),
                }
            }
        };
        match self.power_of {
            Some(base) => format!("a power of {base} {bounds}"),
            None => bounds,
        }
    }
}

fn is_power_of(x: f64, base: u32) -> bool {
    if x < 1.0 || x.fract() != 0.0 {
        return false;
    }
    let mut p = 1.0;
    while p < x {
        p *= base as f64;
    }
    p == x
}

/// The named choices of a `Param<E>` with `E: Choices` (`--upsample nearest`).
pub trait Choices: Copy + PartialEq + 'static {
    /// Every choice: its CLI name and help, in order.
    const NAMES: &'static [(&'static str, &'static str)];
    fn index(self) -> usize;
    fn from_index(i: usize) -> Self;
}

/// How a Rust type is kept as a `Value`.
pub trait ParamType: Copy + PartialEq + 'static {
    fn to_value(self) -> Value;
    fn from_value(v: Value) -> Option<Self>;
    /// The value as the CLI writes it.
    fn text(self) -> String;
    /// Parses what the CLI was given (the range is checked separately).
    fn parse(text: &str) -> Result<Self, String>;
    /// The value as a number, for range checks (`None`: not numeric).
    fn number(self) -> Option<f64>;
    /// The possible values, for choices and switches.
    fn names() -> Option<Vec<&'static str>> {
        None
    }
    /// `--help`'s value name: the possible values (`on|off`), or `N`.
    fn value_name() -> String {
        match Self::names() {
            Some(n) => n.join("|"),
            None => "N".into(),
        }
    }
}

impl ParamType for f32 {
    fn to_value(self) -> Value {
        Value::Real(self)
    }
    fn from_value(v: Value) -> Option<Self> {
        match v {
            Value::Real(x) => Some(x),
            _ => None,
        }
    }
    fn text(self) -> String {
        self.to_string()
    }
    fn parse(text: &str) -> Result<Self, String> {
        text.parse()
            .map_err(|_| format!("'{text}' is not a number"))
    }
    fn number(self) -> Option<f64> {
        Some(self as f64)
    }
}

macro_rules! count_type {
    ($t:ty) => {
        impl ParamType for $t {
            fn to_value(self) -> Value {
                Value::Count(self as u64)
            }
            fn from_value(v: Value) -> Option<Self> {
                match v {
                    Value::Count(x) => <$t>::try_from(x).ok(),
                    _ => None,
                }
            }
            fn text(self) -> String {
                self.to_string()
            }
            fn parse(text: &str) -> Result<Self, String> {
                text.parse()
                    .map_err(|_| format!("'{text}' is not a whole number from 0 to {}", <$t>::MAX))
            }
            fn number(self) -> Option<f64> {
                Some(self as f64)
            }
        }
    };
}
count_type!(u32);
count_type!(u64);

/// `on` / `off`.
impl ParamType for bool {
    fn to_value(self) -> Value {
        Value::Switch(self)
    }
    fn from_value(v: Value) -> Option<Self> {
        match v {
            Value::Switch(x) => Some(x),
            _ => None,
        }
    }
    fn text(self) -> String {
        if self { "on" } else { "off" }.into()
    }
    fn parse(text: &str) -> Result<Self, String> {
        match text {
            "on" => Ok(true),
            "off" => Ok(false),
            _ => Err(format!("'{text}' is neither on nor off")),
        }
    }
    fn number(self) -> Option<f64> {
        None
    }
    fn names() -> Option<Vec<&'static str>> {
        Some(vec!["on", "off"])
    }
}

impl<E: Choices> ParamType for E {
    fn to_value(self) -> Value {
        Value::Choice(self.index())
    }
    fn from_value(v: Value) -> Option<Self> {
        match v {
            Value::Choice(i) if i < E::NAMES.len() => Some(E::from_index(i)),
            _ => None,
        }
    }
    fn text(self) -> String {
        E::NAMES[self.index()].0.into()
    }
    fn parse(text: &str) -> Result<Self, String> {
        E::NAMES
            .iter()
            .position(|(n, _)| *n == text)
            .map(E::from_index)
            .ok_or_else(|| {
                let names: Vec<&str> = E::NAMES.iter().map(|(n, _)| *n).collect();
                format!("'{text}' is not one of {}", names.join(", "))
            })
    }
    fn number(self) -> Option<f64> {
        None
    }
    fn names() -> Option<Vec<&'static str>> {
        Some(E::NAMES.iter().map(|(n, _)| *n).collect())
    }
}

/// A parameter's default: a value, or one derived from the other settings
/// (the one function that computes it, which everything then reads through
/// `Param::get`).
#[derive(Clone, Copy)]
pub enum DefaultValue<T: 'static> {
    Fixed(T),
    /// The function, and what it does in words (for `--help`).
    Derived(fn(&RenderSettings) -> T, &'static str),
}

/// A parameter: the CLI option `--NAME`, its help, default and range.
pub struct Param<T: 'static> {
    pub name: &'static str,
    pub help: &'static str,
    pub default: DefaultValue<T>,
    pub range: Range,
}

impl<T: ParamType> Param<T> {
    /// The value in `s`: the one set, or the default.
    pub fn get(&self, s: &RenderSettings) -> T {
        match s.params.get(self.name).and_then(T::from_value) {
            Some(v) => v,
            None => self.default_in(s),
        }
    }

    /// The default the value would have in `s`.
    pub fn default_in(&self, s: &RenderSettings) -> T {
        match self.default {
            DefaultValue::Fixed(v) => v,
            DefaultValue::Derived(f, _) => f(s),
        }
    }

    /// Sets the value in `s` (checked by `check`, before a run).
    pub fn set(&self, s: &mut RenderSettings, v: T) {
        s.params.0.insert(self.name, v.to_value());
    }

    /// Whether `v` is in the range.
    pub fn accepts(&self, v: T) -> bool {
        v.number().is_none_or(|x| self.range.contains(x))
    }

    /// `v` moved into the range from `from` (see `Range::clamp_from`), as a
    /// number (non-numeric values: 0).
    pub fn clamp_from(&self, from: T, v: T) -> f64 {
        let (a, b) = (from.number().unwrap_or(0.0), v.number().unwrap_or(0.0));
        self.range.clamp_from(a, b)
    }
}

/// A parameter whatever its type: what the registry lists and the CLI,
/// checks and reports go through.
pub trait AnyParam: Sync {
    fn name(&self) -> &'static str;
    fn help(&self) -> &'static str;
    fn range(&self) -> &Range;
    /// The default as text: the value, or what derives it.
    fn default_text(&self) -> String;
    /// `--help`'s value name: `<on|off>`, `<N>`.
    fn value_name(&self) -> String;
    /// Parses a CLI value: its type only; the range is checked with the
    /// other settings (`check`), so every range error reads alike.
    fn parse(&self, text: &str) -> Result<Value, String>;
    /// The value `s` holds (set or default), as text.
    fn text_in(&self, s: &RenderSettings) -> String;
    /// Whether `s` holds the default value (set to it or not set at all).
    fn is_default_in(&self, s: &RenderSettings) -> bool;
    /// Whether `s` sets this parameter explicitly.
    fn is_set_in(&self, s: &RenderSettings) -> bool {
        s.params.get(self.name()).is_some()
    }
    /// Fails with a message naming the option when `s`'s value is out of range.
    fn check(&self, s: &RenderSettings) -> Result<()>;
    /// The value `s` holds times `factor`, kept inside the range (a step
    /// toward an open bound goes halfway to it), or `None` for a parameter
    /// that is not a number (the viewer's keys scale a method's main knob).
    fn scaled_in(&self, s: &RenderSettings, factor: f64) -> Option<Value>;
}

impl<T: ParamType + Sync> AnyParam for Param<T> {
    fn name(&self) -> &'static str {
        self.name
    }
    fn help(&self) -> &'static str {
        self.help
    }
    fn range(&self) -> &Range {
        &self.range
    }
    fn default_text(&self) -> String {
        match self.default {
            DefaultValue::Fixed(v) => v.text(),
            DefaultValue::Derived(_, how) => how.into(),
        }
    }
    fn value_name(&self) -> String {
        T::value_name()
    }
    fn parse(&self, text: &str) -> Result<Value, String> {
        Ok(T::parse(text)?.to_value())
    }
    fn text_in(&self, s: &RenderSettings) -> String {
        self.get(s).text()
    }
    fn is_default_in(&self, s: &RenderSettings) -> bool {
        self.get(s) == self.default_in(s)
    }
    fn scaled_in(&self, s: &RenderSettings, factor: f64) -> Option<Value> {
        let v = self.get(s);
        let old = v.number()?;
        let new = self.range.clamp_from(old, old * factor);
        match v.to_value() {
            Value::Real(_) => Some(Value::Real(new as f32)),
            Value::Count(_) => Some(Value::Count(new.round().max(0.0) as u64)),
            Value::Switch(_) | Value::Choice(_) => None,
        }
    }
    fn check(&self, s: &RenderSettings) -> Result<()> {
        if let Some(v) = s.params.get(self.name) {
            if T::from_value(v).is_none() {
                bail!(
                    "--{}: {v:?} is not a value of this parameter's type",
                    self.name
                );
            }
        }
        let v = self.get(s);
        if !self.accepts(v) {
            bail!(
                "--{} {}: must be {} ({})",
                self.name,
                v.text(),
                self.range.describe(),
                self.help
            );
        }
        Ok(())
    }
}

/// The parameter values a run sets, by name (unset ones take their default).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Params(pub BTreeMap<&'static str, Value>);

impl Params {
    pub const fn new() -> Self {
        Params(BTreeMap::new())
    }

    pub fn get(&self, name: &str) -> Option<Value> {
        self.0.get(name).copied()
    }

    /// These values with `p` set to `v`.
    pub fn with<T: ParamType>(mut self, p: &Param<T>, v: T) -> Self {
        self.0.insert(p.name, v.to_value());
        self
    }

    /// Sets `name` to `v` (a value `AnyParam::parse` made).
    pub fn insert(&mut self, name: &'static str, v: Value) {
        self.0.insert(name, v);
    }

    /// Every value of `other` over these.
    pub fn overlay(&mut self, other: &Params) {
        for (k, v) in &other.0 {
            self.0.insert(k, *v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        let open = Range::open(0.0, 1.0);
        assert!(open.contains(0.5) && !open.contains(0.0) && !open.contains(1.0));
        assert!(!open.contains(f64::NAN));
        let p4 = Range::powers_of(4, 1.0, 4096.0);
        assert!(p4.contains(1.0) && p4.contains(256.0) && !p4.contains(128.0));
        assert!(!p4.contains(16384.0) && !p4.contains(0.0));
        assert_eq!(open.describe(), "within (0, 1)");
        assert_eq!(p4.describe(), "a power of 4 from 1 to 4096");
        // Steps toward an open bound approach it; a closed one clamps.
        assert_eq!(open.clamp_from(0.8, 1.6), 0.9);
        assert_eq!(open.clamp_from(0.001, 0.0005), 0.0005);
        assert_eq!(Range::closed(0.0, 180.0).clamp_from(170.0, 200.0), 180.0);
    }

    #[test]
    fn values_round_trip_and_defaults_derive() {
        const P: Param<u32> = Param {
            name: "test-count",
            help: "A count: for the test.",
            default: DefaultValue::Derived(|s| s.width / 2, "half the width"),
            range: Range::powers_of(2, 1.0, 64.0),
        };
        let mut s = RenderSettings::DEFAULT;
        assert_eq!(P.get(&s), 256);
        assert!(P.is_default_in(&s) && !P.is_set_in(&s));
        P.set(&mut s, 8);
        assert_eq!(P.get(&s), 8);
        assert!(!P.is_default_in(&s) && P.check(&s).is_ok());
        P.set(&mut s, 3);
        let e = P.check(&s).unwrap_err().to_string();
        assert_eq!(
            e,
            "--test-count 3: must be a power of 2 from 1 to 64 (A count: for the test.)"
        );
        assert_eq!(P.parse("16"), Ok(Value::Count(16)));
        assert!(P.parse("x").is_err() && P.parse("-1").is_err());
        assert_eq!(P.default_text(), "half the width");
    }
}
