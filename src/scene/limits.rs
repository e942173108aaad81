//! Budgets a scene file is checked against before the loader does the work
//! they bound, so that a small hostile file cannot make `isr` allocate or loop
//! without bound. Each limit is generous for real scenes; a file over one gets
//! an error that names what is too large and the limit. `docs/security.md`
//! lists them.

/// What a scene may ask of the loader. [`Limits::DEFAULT`] is what `isr`
/// uses; tests (the fuzzer) pass tighter ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Bytes of the `.gltf`/`.glb` file itself.
    pub scene_file_bytes: u64,
    /// Bytes of all buffers together (their declared `byteLength`s), checked
    /// before any buffer is read.
    pub buffer_bytes: u64,
    /// Bytes of one image file, checked before it is read.
    pub image_file_bytes: u64,
    /// Width and height of one texture, read from the image header before decoding.
    pub texture_dimension: u32,
    /// Pixels of all textures together, checked from the headers before decoding
    /// (4 bytes each once decoded).
    pub texture_pixels: u64,
    /// Nodes visited while instancing: a node listed under several parents is
    /// visited once per path to it, so a small file can describe 2^40 visits.
    pub node_visits: u64,
    /// Nesting depth of the node hierarchy.
    pub hierarchy_depth: u64,
    /// Triangles of all mesh instances together.
    pub triangles: u64,
    /// Vertices of all mesh instances together (bounds every per-vertex array,
    /// including sparse accessors, which need no data to declare a count).
    pub vertices: u64,
    /// Largest world-space coordinate, in metres. The renderer works in f32:
    /// beyond about 1e19 the shaders' squared distances overflow (NaN normals
    /// and an infinite default light at 1e18 and 1e30 were issue 14), and
    /// well before that its shadow test loses precision (measured on
    /// lavapipe: correct at 1e6 m, degraded at 3e6, black at 1e7).
    pub coordinate: f32,
    /// Smallest extent (the diagonal of the geometry's bounds), in metres.
    /// Images do not depend on a scene's size (`tests/scale.rs`) until its
    /// areas and squared distances near f32's smallest normal numbers:
    /// measured correct for a 2 m box scaled by 1e-8, broken at 1e-10.
    pub min_extent: f32,
}

impl Limits {
    pub const DEFAULT: Limits = Limits {
        scene_file_bytes: 2 << 30,
        buffer_bytes: 2 << 30,
        image_file_bytes: 256 << 20,
        texture_dimension: 16384,
        texture_pixels: 1 << 27,
        node_visits: 1 << 20,
        hierarchy_depth: 256,
        triangles: 1 << 24,
        vertices: 1 << 24,
        coordinate: 1e6,
        min_extent: 1e-6,
    };
}

impl Default for Limits {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Bytes in a human unit for messages ("256 MiB").
pub fn bytes(n: u64) -> String {
    const UNITS: [&str; 4] = ["bytes", "KiB", "MiB", "GiB"];
    let mut v = n as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{n} bytes")
    } else if v.fract() == 0.0 {
        format!("{v:.0} {}", UNITS[u])
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}
