//! What a run is asked to render: resolution, method and every method's
//! parameters, with one set of defaults (`RenderSettings::DEFAULT`) that the
//! CLI, the library and the benchmarks share. Values derived from the
//! settings (levels, depths, VPL counts) are computed here, once.

/// How indirect light is computed. Each variant is one module of `methods`
/// (the factory is `methods::create`); the doc comment is its CLI help.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// Direct light only: indirect irradiance is zero.
    None,
    /// Stenciled gathering from N regular VPLs into the multiresolution buffer.
    MultiresGather,
    /// Basic ISR: per-frame clustered light patches, gathered by every eye patch.
    Isr,
    /// Hierarchical ISR: a per-fragment traversal of the RSM quadtree.
    Hisr,
    /// Every full-resolution pixel gathers N regular VPLs.
    RsmGather,
    /// Each VPL splats a full-screen quad, additively.
    RsmSplat,
    /// Each VPL splats a quad bounded to where it can exceed --splat-threshold.
    RsmSplatRestricted,
    /// Each VPL splats into every patch of the multiresolution buffer.
    MultiresSplat,
    /// Every pixel gathers every RSM texel (R^2 VPLs), in chunks.
    Reference,
    /// One-bounce path tracing with indirect visibility, on the CPU.
    Pathtrace,
}

impl Method {
    /// The name the CLI and the reports use (`multires-gather`).
    pub fn name(self) -> &'static str {
        match self {
            Method::None => "none",
            Method::MultiresGather => "multires-gather",
            Method::Isr => "isr",
            Method::Hisr => "hisr",
            Method::RsmGather => "rsm-gather",
            Method::RsmSplat => "rsm-splat",
            Method::RsmSplatRestricted => "rsm-splat-restricted",
            Method::MultiresSplat => "multires-splat",
            Method::Reference => "reference",
            Method::Pathtrace => "pathtrace",
        }
    }

    /// Every method, in the CLI's order.
    pub fn all() -> &'static [Method] {
        use clap::ValueEnum as _;
        Self::value_variants()
    }

    /// Whether the method goes through the multiresolution buffer.
    pub fn uses_multires(self) -> bool {
        matches!(
            self,
            Method::MultiresGather | Method::Isr | Method::Hisr | Method::MultiresSplat
        )
    }

    /// Whether the method reads N regular VPLs (`--vpls`).
    pub fn uses_regular_vpls(self) -> bool {
        !matches!(self, Method::None | Method::Reference | Method::Pathtrace)
    }
}

/// The light-space hierarchy (docs/algorithm.md section 4).
#[derive(Clone, Debug, PartialEq)]
pub struct LightTreeSettings {
    /// A patch is valid (one surface) when each non-empty child's mean lies
    /// within this fraction of its distance to the light (for an orthographic
    /// RSM, of the RSM's half side) of the patch's plane (`rsm_tree.comp`).
    pub depth_threshold: f32,
    /// ... and their normals by less than this angle (degrees).
    pub normal_threshold_deg: f32,
    /// Basic ISR's dense starting level: patches per side (a power of 2, at most R).
    pub isr_base: u32,
    /// HISR starts from 2^s x 2^s patches.
    pub start_level: u32,
    /// HISR subdivides down to 2^d x 2^d patches (`None`: 6, or log2 R if
    /// smaller). Invalid patches are always subdivided down to this depth, so
    /// it bounds the cost of discontinuities in light space.
    pub max_depth: Option<u32>,
    /// HISR's error threshold tau, as a fraction of the light's peak intensity.
    pub tau: f32,
    /// HISR's eye-space tiles cover 2^K, 2^(K+1) and 2^(K+2) pixels a side
    /// (three chained levels): the traversal shared by a tile's receivers is
    /// found once per tile (`hisr-cut`, docs/algorithm.md section 4.4). 0:
    /// every fragment traverses from the roots.
    pub hisr_tile_level: u32,
}

impl LightTreeSettings {
    pub const DEFAULT: Self = Self {
        depth_threshold: 0.1,
        normal_threshold_deg: 30.0,
        isr_base: 64,
        start_level: 2,
        max_depth: None,
        tau: 0.05,
        hisr_tile_level: 4,
    };
}

impl Default for LightTreeSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// How a regular VPL stands for its RSM patch (docs/algorithm.md section 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum VplSampling {
    /// The patch's mean position and normal, summed flux and area.
    Mean,
    /// The texel at the patch centre, flux and area scaled by the texel count.
    Point,
}

/// Upsampling of the multiresolution buffer to full resolution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Upsample {
    /// Bilinear between neighbouring patches, renormalised, never across a discontinuity.
    Interpolated,
    /// Each pixel takes the value of the patch that covers it.
    Nearest,
}

/// The eye-space hierarchy (docs/algorithm.md section 3).
#[derive(Clone, Debug, PartialEq)]
pub struct MultiresSettings {
    /// Coarsest level L (level l texels cover 2^l x 2^l pixels); `None` picks
    /// one from the resolution (`default_levels`).
    pub levels: Option<u32>,
    /// A texel is smooth when its view-depth range, relative to its nearest
    /// depth, is below this: `(max - min) / min < t`.
    pub depth_threshold: f32,
    /// ... and when the normals in it span less than this angle (degrees),
    /// measured as the diagonal of their component-wise bounding box.
    pub normal_threshold_deg: f32,
    pub upsample: Upsample,
    /// Early stencil rejection in the gather (`false`: shade every texel of
    /// every layer and mask afterwards, for measuring what the stencil saves).
    pub stencil: bool,
}

impl MultiresSettings {
    pub const DEFAULT: Self = Self {
        levels: None,
        depth_threshold: 0.1,
        normal_threshold_deg: 20.0,
        upsample: Upsample::Interpolated,
        stencil: true,
    };
}

impl Default for MultiresSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Coarsest level for a resolution: texels of level L are about 1/16 of the
/// shorter side (L = 5 at 512, 6 at 1024), at most 8.
pub fn default_levels(width: u32, height: u32) -> u32 {
    (width.min(height).max(2).ilog2().saturating_sub(4)).clamp(1, 8)
}

/// The largest `--hisr-tile-level` (tiles of 256 x 256 pixels).
pub const HISR_MAX_TILE_LEVEL: u32 = 8;

/// The largest number of levels the patch-count buffer holds.
pub const MAX_LEVELS: u32 = 16;

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// RSM resolution R (R x R texels), a power of two.
    pub rsm_resolution: u32,
    pub method: Method,
    /// Multiplier applied to radiance before the PNG's sRGB encoding.
    pub exposure: f32,
    /// Shadow-map normal offset, in RSM texels at the receiver.
    pub shadow_normal_offset: f32,
    /// Constant relative depth bias of the shadow test (fraction of the distance).
    pub shadow_depth_bias: f32,
    /// PCF tap spacing in RSM texels.
    pub pcf_radius: f32,
    /// Slope-scaled shadow bias, in RSM texels along the receiver's slope.
    pub shadow_slope_bias: f32,
    /// Regular VPLs for the VPL methods: a power of 4, at most R^2.
    pub vpls: u32,
    pub vpl_sampling: VplSampling,
    pub multires: MultiresSettings,
    pub light_tree: LightTreeSettings,
    /// Restricted splats skip where a VPL's irradiance bound is below this (W/m^2).
    pub splat_threshold: f32,
    /// The reference's light-patch evaluations per submission: about 0.5 s on
    /// lavapipe at the default, milliseconds on a GPU.
    pub reference_chunk: u64,
}

impl RenderSettings {
    /// The defaults of the CLI, of `Default` and of the benchmarks.
    pub const DEFAULT: Self = Self {
        width: 512,
        height: 512,
        rsm_resolution: 512,
        method: Method::MultiresGather,
        exposure: 1.0,
        shadow_normal_offset: 1.5,
        shadow_depth_bias: 5e-4,
        pcf_radius: 1.0,
        shadow_slope_bias: 2.5,
        vpls: 256,
        vpl_sampling: VplSampling::Mean,
        multires: MultiresSettings::DEFAULT,
        light_tree: LightTreeSettings::DEFAULT,
        splat_threshold: 0.01,
        reference_chunk: 1 << 26,
    };

    /// The coarsest level L of the multiresolution buffer.
    pub fn levels(&self) -> u32 {
        self.multires
            .levels
            .unwrap_or_else(|| default_levels(self.width, self.height))
    }

    /// HISR's deepest level: `--max-depth`, by default 6 or log2 R if smaller.
    pub fn hisr_max_depth(&self) -> u32 {
        self.light_tree
            .max_depth
            .unwrap_or(6.min(self.rsm_resolution.max(1).ilog2()))
    }

    /// The regular VPLs the method uses: every RSM texel for `reference`.
    pub fn effective_vpls(&self) -> u32 {
        match self.method {
            Method::Reference => self.rsm_resolution * self.rsm_resolution,
            _ => self.vpls,
        }
    }

    /// The RSM quadtree level (mip) Basic ISR starts from.
    pub fn isr_base_mip(&self) -> u32 {
        self.rsm_resolution.ilog2()
            - self
                .light_tree
                .isr_base
                .clamp(1, self.rsm_resolution)
                .ilog2()
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_names_are_the_cli_names() {
        use clap::ValueEnum as _;
        for m in Method::all() {
            assert_eq!(m.to_possible_value().unwrap().get_name(), m.name());
        }
    }

    #[test]
    fn derived_values() {
        let s = RenderSettings {
            rsm_resolution: 256,
            ..RenderSettings::DEFAULT
        };
        assert_eq!(s.levels(), 5);
        assert_eq!(s.hisr_max_depth(), 6);
        assert_eq!(s.isr_base_mip(), 2);
        let r = RenderSettings {
            method: Method::Reference,
            rsm_resolution: 32,
            ..s
        };
        assert_eq!(r.effective_vpls(), 1024);
    }
}
