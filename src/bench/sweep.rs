//! The points the bench renders (docs/algorithm.md section 6.5): every
//! method's own sweep (`methods::Descriptor::sweep`: VPL counts for the
//! regular methods, the base level for Basic ISR, tau, max depth and the
//! eye-space refinement threshold for HISR). One point of each sweep is the
//! method's default, used by the gallery and the per-pass chart.

use crate::methods::{self, Descriptor};
use crate::settings::{Method, Params, RenderSettings};

/// The methods the bench sweeps, in report order: every registered method
/// with a sweep.
pub fn methods() -> Vec<Method> {
    methods::REGISTRY
        .iter()
        .filter(|d| {
            !d.sweep(RenderSettings::DEFAULT.rsm_resolution, true)
                .is_empty()
        })
        .map(|d| d.key())
        .collect()
}

/// One point of a sweep: the method and the parameter values it sets.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    pub method: Method,
    pub params: Params,
}

impl Config {
    fn descriptor(&self) -> &'static dyn Descriptor {
        methods::find(self.method).expect("a sweep point names a registered method")
    }

    /// The settings this point renders with: `base`'s, with this point's
    /// values over them.
    pub fn settings(&self, base: &RenderSettings) -> RenderSettings {
        let mut s = base.clone().with_method(self.method);
        s.params.overlay(&self.params);
        s
    }

    /// Whether this point renders with the values `base` gives the method's
    /// parameters (the method's defaults, unless the run set some).
    pub fn is_default(&self, base: &RenderSettings) -> bool {
        let d = self.descriptor();
        methods::same_params(
            d,
            &self.settings(base),
            &base.clone().with_method(self.method),
        )
    }

    /// A short label for tables and charts: "256 VPLs", "base 64", "tau 0.05".
    pub fn label(&self, base: &RenderSettings) -> String {
        self.descriptor().label(&self.settings(base))
    }
}

/// The sweep of `method` for RSM resolution `rsm`; `quick` keeps two or three points.
pub fn sweep(method: Method, rsm: u32, quick: bool) -> Vec<Config> {
    let Ok(d) = methods::find(method) else {
        return vec![];
    };
    let mut out: Vec<Config> = d
        .sweep(rsm, quick)
        .into_iter()
        .map(|params| Config { method, params })
        .collect();
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_swept_method_has_its_default_in_its_sweep() {
        let base = RenderSettings {
            rsm_resolution: 128,
            ..RenderSettings::DEFAULT
        };
        let all = methods();
        // Every method but direct light alone and the dense reference.
        let expected: Vec<Method> = crate::methods::REGISTRY
            .iter()
            .map(|d| d.key())
            .filter(|m| !matches!(m.name(), "none" | "reference"))
            .collect();
        assert_eq!(all, expected);
        for quick in [false, true] {
            for &m in &all {
                let s = sweep(m, 128, quick);
                assert!(!s.is_empty());
                let defaults = s.iter().filter(|c| c.is_default(&base)).count();
                assert_eq!(defaults, 1, "{} quick={quick}", m.name());
            }
        }
        assert!(sweep(crate::methods::reference::KEY, 128, false).is_empty());
    }

    #[test]
    fn labels_name_the_swept_value() {
        let base = RenderSettings {
            rsm_resolution: 128,
            ..RenderSettings::DEFAULT
        };
        let labels: Vec<String> = sweep(crate::methods::hisr::KEY, 128, true)
            .iter()
            .map(|c| c.label(&base))
            .collect();
        assert_eq!(labels, ["tau 0.2, depth 7", "tau 0.05, depth 7"]);
    }
}
