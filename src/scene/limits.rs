//! Budgets a scene file is checked against before the loader does the work
//! they bound, so that a small hostile file cannot make `isr` allocate or loop
//! without bound. Each limit is generous for real scenes; a file over one gets
//! an error that names what is too large and the limit. `docs/security.md`
//! lists them.

/// What a scene may ask of the loader. [`Limits::DEFAULT`] is what `isr`
/// uses; tests (the fuzzer) pass tighter ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Bytes of the `.gltf`/`.glb`/`.obj` file itself (an OBJ is checked
    /// before it is read, then read line by line, never whole).
    pub scene_file_bytes: u64,
    /// Bytes of one line of an OBJ or MTL file (a line is held whole while
    /// it is parsed; a face of 10^6 vertices is about 7 MB).
    pub line_bytes: u64,
    /// Bytes of all MTL material libraries of an OBJ together, each checked
    /// before it is read.
    pub material_library_bytes: u64,
    /// Bytes of a scene description (`NAME.scene.json`).
    pub description_bytes: u64,
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
    /// Triangles of all mesh instances together (an OBJ's polygons counted
    /// as the triangles they fan into, as each face is read).
    pub triangles: u64,
    /// Vertices of all mesh instances together (bounds every per-vertex array,
    /// including sparse accessors, which need no data to declare a count;
    /// in an OBJ, each of the `v`, `vt` and `vn` lists as it is read, and the
    /// distinct vertices its faces make).
    pub vertices: u64,
    /// Largest world-space coordinate, in metres. The renderer works in f32:
    /// beyond about 1e19 the shaders' squared distances overflow (NaN normals
    /// and an infinite default light at 1e18 and 1e30 were issue 14), and
    /// well before that its shadow test loses precision (measured on
    /// lavapipe: correct at 1e6 m, degraded at 3e6, black at 1e7).
    pub coordinate: f32,
    /// Largest texture coordinate (in repeats of the texture, either sign).
    /// Beyond it a coordinate keeps too few bits for a texel in f32, and at
    /// 3e38 the rasterizer's interpolation overflows to NaN in every pixel.
    pub texcoord: f32,
    /// Materials of a scene (in an OBJ, every `newmtl` of its libraries
    /// counts, defined or used): one mesh is made per material used, so this
    /// also bounds the meshes an OBJ makes however often it switches.
    pub materials: u64,
    /// Smallest extent (the diagonal of the geometry's bounds), in metres.
    /// Images do not depend on a scene's size (`tests/scale.rs`) until its
    /// areas and squared distances near f32's smallest normal numbers:
    /// measured correct for a 2 m box scaled by 1e-8, broken at 1e-10.
    pub min_extent: f32,
}

impl Limits {
    pub const DEFAULT: Limits = Limits {
        scene_file_bytes: 2 << 30,
        line_bytes: 64 << 20,
        material_library_bytes: 64 << 20,
        description_bytes: 1 << 20,
        buffer_bytes: 2 << 30,
        image_file_bytes: 256 << 20,
        texture_dimension: 16384,
        texture_pixels: 1 << 27,
        node_visits: 1 << 20,
        hierarchy_depth: 256,
        triangles: 1 << 20,
        vertices: 1 << 21,
        coordinate: 1e6,
        texcoord: 65536.0,
        materials: 1 << 16,
        min_extent: 1e-6,
    };

    /// The tight budgets of the fuzz targets (`fuzz/`) and the stable fuzz
    /// tests (`tests/fuzz_loader*.rs`): what they allow is small, so an
    /// allocation no budget accounts for stands out (tests/fuzz_loader.rs
    /// holds each load to 96 MiB at its peak).
    pub const FUZZ: Limits = Limits {
        scene_file_bytes: 8 << 20,
        line_bytes: 1 << 20,
        material_library_bytes: 1 << 20,
        description_bytes: 1 << 16,
        buffer_bytes: 8 << 20,
        image_file_bytes: 1 << 20,
        texture_dimension: 1024,
        texture_pixels: 1 << 18,
        node_visits: 1 << 12,
        hierarchy_depth: 64,
        triangles: 1 << 15,
        vertices: 1 << 15,
        coordinate: 1e6,
        texcoord: 65536.0,
        materials: 1 << 10,
        min_extent: 1e-6,
    };
}

impl Limits {
    /// That `scene`'s geometry is neither too far out nor too small for f32
    /// rendering (`coordinate`, `min_extent`); `shrink` says how to scale a
    /// scene down in the loader's terms. Its bounds if so.
    pub fn check_extent(
        &self,
        scene: &super::Scene,
        shrink: &str,
    ) -> anyhow::Result<(glam::Vec3, glam::Vec3)> {
        let (lo, hi) = scene
            .bounds()
            .ok_or_else(|| anyhow::anyhow!("the scene has no vertices to render"))?;
        // In world metres: the scene's origin counted in, in f64.
        let o = scene.origin;
        let reach = ((o + lo.as_dvec3()).abs())
            .max((o + hi.as_dvec3()).abs())
            .max_element() as f32;
        if reach.is_nan() || reach > self.coordinate {
            anyhow::bail!(
                "the scene is too large: its geometry reaches {reach:.3e} m from the origin; isr renders in 32-bit floats and supports coordinates up to {:.0e} m ({shrink})",
                self.coordinate
            );
        }
        let extent = (hi - lo).length();
        if extent < self.min_extent {
            anyhow::bail!(
                "the scene is too small: its geometry spans {extent:.3e} m; isr renders in 32-bit floats and supports scenes at least {:.0e} m across (scale the scene up: images do not depend on the scale)",
                self.min_extent
            );
        }
        Ok((lo, hi))
    }
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
