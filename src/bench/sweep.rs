//! Each method's parameter sweep (docs/algorithm.md section 6.5): VPL counts
//! for the regular methods, the base level for Basic ISR, tau, max depth and
//! the eye-space refinement threshold for HISR. One point of each sweep is the
//! method's default (`RenderSettings::DEFAULT`), used by the gallery and the
//! per-pass chart.

use crate::settings::{Method, RenderSettings};

/// The methods the bench sweeps, in report order.
pub const METHODS: &[Method] = &[
    Method::RsmGather,
    Method::RsmSplat,
    Method::RsmSplatRestricted,
    Method::MultiresSplat,
    Method::MultiresGather,
    Method::Isr,
    Method::Hisr,
];

/// One point of a sweep: the method and what it changes from the defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    pub method: Method,
    pub vpls: Option<u32>,
    pub isr_base: Option<u32>,
    pub tau: Option<f32>,
    pub max_depth: Option<u32>,
    /// Eye-space refinement: `MultiresSettings::depth_threshold`.
    pub depth_threshold: Option<f32>,
}

impl Config {
    fn new(method: Method) -> Self {
        Self {
            method,
            vpls: None,
            isr_base: None,
            tau: None,
            max_depth: None,
            depth_threshold: None,
        }
    }

    /// The settings this point renders with.
    pub fn settings(&self, base: &RenderSettings) -> RenderSettings {
        let mut s = base.clone();
        s.method = self.method;
        if let Some(v) = self.vpls {
            s.vpls = v;
        }
        if let Some(b) = self.isr_base {
            s.light_tree.isr_base = b;
        }
        if let Some(t) = self.tau {
            s.light_tree.tau = t;
        }
        if self.max_depth.is_some() {
            s.light_tree.max_depth = self.max_depth;
        }
        if let Some(d) = self.depth_threshold {
            s.multires.depth_threshold = d;
        }
        s
    }

    /// Whether this point renders with the method's default settings.
    pub fn is_default(&self, base: &RenderSettings) -> bool {
        let d = RenderSettings {
            method: self.method,
            ..base.clone()
        };
        let mut s = self.settings(base);
        // An explicit max depth equal to the derived default is the default.
        if s.light_tree.max_depth == Some(d.hisr_max_depth()) {
            s.light_tree.max_depth = None;
        }
        s.vpls == RenderSettings::DEFAULT.vpls
            && s.light_tree == RenderSettings::DEFAULT.light_tree
            && s.multires == RenderSettings::DEFAULT.multires
    }

    /// A short label for tables and charts: "256 VPLs", "base 64", "tau 0.05".
    pub fn label(&self, base: &RenderSettings) -> String {
        let s = self.settings(base);
        match self.method {
            Method::Isr => format!("base {}", s.light_tree.isr_base),
            Method::Hisr => {
                let mut l = format!("tau {}, depth {}", s.light_tree.tau, s.hisr_max_depth());
                if s.multires.depth_threshold != RenderSettings::DEFAULT.multires.depth_threshold {
                    l += &format!(", eye depth {}", s.multires.depth_threshold);
                }
                l
            }
            _ => format!("{} VPLs", s.vpls),
        }
    }
}

/// The sweep of `method` for RSM resolution `rsm` (VPL counts and bases are
/// capped by what the RSM holds); `quick` keeps two or three points.
pub fn sweep(method: Method, rsm: u32, quick: bool) -> Vec<Config> {
    let c = || Config::new(method);
    let mut out: Vec<Config> = match method {
        Method::Isr => {
            let bases: &[u32] = if quick { &[16, 64] } else { &[16, 32, 64] };
            bases
                .iter()
                .filter(|&&b| b <= rsm)
                .map(|&b| Config {
                    isr_base: Some(b),
                    ..c()
                })
                .collect()
        }
        Method::Hisr => {
            // Large taus trace the cheap end of HISR's front (at tau 0.97
            // a valid patch splits only for receivers very near it, while
            // invalid ones are still held to tau / 100); smaller max depths
            // at the two largest taus go cheaper still.
            let taus: &[f32] = if quick {
                &[0.2, 0.05]
            } else {
                &[0.97, 0.94, 0.9, 0.75, 0.5, 0.2, 0.05, 0.01]
            };
            let mut v: Vec<Config> = taus
                .iter()
                .map(|&t| Config {
                    tau: Some(t),
                    ..c()
                })
                .collect();
            if !quick {
                let deepest = 6.min(rsm.ilog2());
                for t in [0.97, 0.9] {
                    for d in [deepest.saturating_sub(3), deepest.saturating_sub(2)] {
                        if d >= RenderSettings::DEFAULT.light_tree.start_level {
                            v.push(Config {
                                tau: Some(t),
                                max_depth: Some(d),
                                ..c()
                            });
                        }
                    }
                }
                for t in [0.05, 0.3] {
                    v.push(Config {
                        depth_threshold: Some(t),
                        ..c()
                    });
                }
                // The accurate end: one level deeper (single RSM texels at
                // RSM 128), where the default depth stops near the error of
                // 4^6 = 4096 VPLs.
                if rsm.ilog2() > deepest {
                    for t in [0.2, 0.1, 0.05, 0.01] {
                        v.push(Config {
                            tau: Some(t),
                            max_depth: Some(deepest + 1),
                            ..c()
                        });
                    }
                }
            }
            v
        }
        Method::None | Method::Reference | Method::Pathtrace => vec![],
        _ => {
            let counts: &[u32] = if quick {
                &[64, 256]
            } else {
                &[64, 256, 1024, 4096]
            };
            counts
                .iter()
                .filter(|&&n| n <= rsm * rsm)
                .map(|&n| Config {
                    vpls: Some(n),
                    ..c()
                })
                .collect()
        }
    };
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_method_has_its_default_in_its_sweep() {
        let base = RenderSettings {
            rsm_resolution: 128,
            ..RenderSettings::DEFAULT
        };
        for quick in [false, true] {
            for &m in METHODS {
                let s = sweep(m, 128, quick);
                assert!(!s.is_empty());
                let defaults = s.iter().filter(|c| c.is_default(&base)).count();
                assert_eq!(defaults, 1, "{} quick={quick}", m.name());
            }
        }
        assert!(sweep(Method::Reference, 128, false).is_empty());
    }

    #[test]
    fn counts_are_capped_by_the_rsm() {
        let s = sweep(Method::RsmGather, 16, false);
        assert_eq!(
            s.iter().map(|c| c.vpls.unwrap()).collect::<Vec<_>>(),
            [64, 256]
        );
    }
}
