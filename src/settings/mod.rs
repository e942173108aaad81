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
    /// The direct light's shadow map S (S x S, a power of two; 0: chosen
    /// from the image size, `shadow_size`).
    pub shadow_resolution: u32,
    /// A directional light's shadow map fitted to the camera's view (else
    /// the RSM's square, fixed while the camera moves: for comparisons).
    pub fit_sun_shadow: bool,
    pub method: Method,
    /// Multiplier applied to radiance before the PNG's sRGB encoding.
    pub exposure: f32,
    /// Shadow-map normal offset, in shadow-map texels at the receiver (0: every PCF
    /// tap compares against the receiver's own plane instead, which does
    /// not shift shadows sideways; kept for experiments).
    pub shadow_normal_offset: f32,
    /// Constant depth bias of the shadow test: relative to the distance for
    /// perspective RSMs, a fraction of the depth range for orthographic ones.
    pub shadow_depth_bias: f32,
    /// PCF tap spacing in shadow-map texels.
    pub pcf_radius: f32,
    /// Receiver-plane bias: how many shadow-map texels of the receiver plane's
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
        shadow_resolution: 0,
        fit_sun_shadow: true,
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

    /// The shadow map's side S (docs/algorithm.md section 2.2): the one
    /// asked for, else 8 texels per pixel of the image's longer side as a
    /// power of two, in 1024..=4096. Eight: a spot's map spans its whole
    /// cone, of which a view sees a part; in the Sibenik nave at 512 x 512
    /// the spot's direct light was 1.2% from the path tracer at S = 2048
    /// and 0.6% at 4096 (`examples/direct_against_truth.rs`). 4096 is the
    /// largest side every Vulkan device takes.
    pub fn shadow_size(&self) -> u32 {
        match self.shadow_resolution {
            0 => (8 * self.width.max(self.height))
                .next_power_of_two()
                .clamp(MIN_AUTO_SHADOW, MAX_AUTO_SHADOW),
            s => s,
        }
    }

    /// The shadow map size a directional light's shadow is fitted at, if
    /// it is fitted to the view (`fit_sun_shadow`).
    pub fn sun_shadow_fit(&self) -> Option<u32> {
        self.fit_sun_shadow.then(|| self.shadow_size())
    }
}

/// The range of the shadow map's default side (`shadow_size`).
pub const MIN_AUTO_SHADOW: u32 = 1024;
pub const MAX_AUTO_SHADOW: u32 = 4096;

impl Default for RenderSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}
