//! What a run is asked to render: resolution, RSM, method and the values of
//! the parameters, with one set of defaults (`RenderSettings::DEFAULT`) that
//! the CLI, the library and the benchmarks share. The parameters themselves
//! (their names, ranges, defaults and derived values) are declared by the
//! modules that read them (`params`); this module only holds their values.

pub mod params;

pub use params::{Choices, Param, ParamType, Params, Range, Value};

/// Which indirect-light method a run uses: the method's CLI name, a key into
/// the registry of `methods` (`methods::find`), where everything else about
/// the method lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Method(&'static str);

impl Method {
    pub const fn new(name: &'static str) -> Self {
        Method(name)
    }

    /// The name the CLI and the reports use (`multires-gather`).
    pub fn name(self) -> &'static str {
        self.0
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// RSM resolution R (R x R texels), a power of two.
    pub rsm_resolution: u32,
    pub method: Method,
    /// Multiplier applied to radiance before the PNG's sRGB encoding.
    pub exposure: f32,
    /// Shadow-map normal offset, in RSM texels at the receiver (0: every PCF
    /// tap compares against the receiver's own plane instead, which does
    /// not shift shadows sideways; kept for experiments).
    pub shadow_normal_offset: f32,
    /// Constant depth bias of the shadow test: relative to the distance for
    /// perspective RSMs, a fraction of the depth range for orthographic ones.
    pub shadow_depth_bias: f32,
    /// PCF tap spacing in RSM texels.
    pub pcf_radius: f32,
    /// Receiver-plane bias: how many RSM texels of the receiver plane's
    /// depth gradient the hardware 2x2 compare may span (its texels lie up
    /// to one texel from the tap: 1).
    pub shadow_slope_bias: f32,
    /// The parameters set to other than their defaults (`Param::get` reads
    /// them, `Param::set` writes them).
    pub params: Params,
}

impl RenderSettings {
    /// The defaults of the CLI, of `Default` and of the benchmarks.
    pub const DEFAULT: Self = Self {
        width: 512,
        height: 512,
        rsm_resolution: 512,
        // The paper's method, at its best balance (docs/results.md).
        method: Method::new("hisr"),
        exposure: 1.0,
        shadow_normal_offset: 0.0,
        shadow_depth_bias: 5e-4,
        pcf_radius: 1.0,
        shadow_slope_bias: 1.0,
        params: Params::new(),
    };

    /// These settings with `p` set to `v`.
    pub fn with<T: ParamType>(mut self, p: &Param<T>, v: T) -> Self {
        p.set(&mut self, v);
        self
    }

    /// These settings with method `m`.
    pub fn with_method(self, method: Method) -> Self {
        Self { method, ..self }
    }

    /// log2 R: the RSM quadtree's top level (one patch).
    pub fn rsm_top_level(&self) -> u32 {
        self.rsm_resolution.max(1).ilog2()
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}
