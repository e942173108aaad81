//! The scene's textures as a few 2D array images, the form in which every
//! conformant device can sample a texture chosen per fragment. A material
//! names an array and a layer; the shader picks the array with a switch over
//! constant indices (`shaders/material.glsl`), which needs no
//! `shaderSampledImageArrayDynamicIndexing`. An array of descriptors indexed
//! by the material's texture would need it, and lavapipe in Mesa 22 lacks it.
//!
//! The plan depends on no device: it keeps within the limits Vulkan
//! guarantees (layers of at most [`MAX_SIDE`] texels a side, [`MAX_LAYERS`]
//! layers an array), so that every device renders the same images and the
//! CPU path tracer samples the same texels ([`fitted`]).
//!
//! The layers of an array share one size. Textures are grouped by their
//! exact size; while that needs more than [`ARRAYS`] arrays, the two groups
//! whose union adds the fewest texels are joined, and then further while the
//! texels that adds stay within [`PAD_TEXELS`] or the textures' own (fewer
//! arrays, fewer samples on a CPU driver). In an array of one size
//! every texture fills its layer, and the sampler filters and repeats it
//! (docs/algorithm.md section 3, step 1). An array of several sizes is
//! *bordered*: each texture sits at texel (1, 1) of a layer two texels
//! larger than the largest, ringed by a copy of its opposite edges
//! ([`bordered`]), and the shader wraps the coordinates into the texture
//! ([`TexturePlan::transform`]), so that the sampler's bilinear taps at the
//! texture's edges read the texels that repeat would: one tap for every
//! texture, and none resampled to join an array (none blurred, none
//! upscaled). Only a texture with a side over [`MAX_SIDE`] is shrunk to fit
//! (area averaging in linear light, [`shrink`]), with a warning
//! ([`warnings`]).

mod shrink;

use crate::scene::limits::Limits;
use crate::scene::Texture;
use anyhow::{bail, Result};
use std::borrow::Cow;
use std::collections::BTreeMap;

/// The largest side of a layer: Vulkan's guaranteed `maxImageDimension2D`.
pub const MAX_SIDE: u32 = 4096;
/// The most layers of one array: Vulkan's guaranteed `maxImageArrayLayers`.
pub const MAX_LAYERS: usize = 256;
/// The arrays a scene binds, each its own binding of set 1; every shader
/// stage may sample 16 images on any device, and the frame set and the
/// methods keep to the other 8.
pub const ARRAYS: usize = 8;
/// The shaders' names of the arrays' bindings (set 1, bindings 1 to 8 of
/// `shaders/material.glsl`), checked against the SPIR-V when the pipelines
/// are made.
pub const BINDING_NAMES: [&str; ARRAYS] = [
    "texture_array_0",
    "texture_array_1",
    "texture_array_2",
    "texture_array_3",
    "texture_array_4",
    "texture_array_5",
    "texture_array_6",
    "texture_array_7",
];
/// Texels that joining groups beyond [`ARRAYS`] may add, when the
/// textures' own texels are fewer (else as many as theirs: texture memory
/// at most doubles). The shader picks an array by a chain of branches, and
/// lavapipe runs every branch, sampling every array, for every fragment:
/// Sponza at 512x512 (`isr render --method none`, lavapipe, 2 cores)
/// renders its G-buffer in 277 ms with its textures in 1 array (31.7 MiB),
/// 296 ms in 2 (21.2 MiB), 486 ms in 4 (12.1 MiB) and 951 ms in 8 (8.4
/// MiB; 8.0 MiB as textures of their own). 16 M texels (64 MiB) puts a
/// scene like Sponza in one array; a GPU branches per draw and pays little
/// either way.
pub const PAD_TEXELS: u64 = 1 << 24;
/// Past this many distinct sizes, sizes are first rounded up to powers of
/// two (at most 13 x 13 classes up to 4096): joining groups costs the cube
/// of their number, and a scene with thousands of sizes is a hostile one.
const EXACT_SIZES: usize = 64;

/// Where one texture lives: layer `layer` of array `array`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    pub array: u32,
    pub layer: u32,
}

/// One array image: every layer `width` x `height`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ArrayPlan {
    pub width: u32,
    pub height: u32,
    /// Layer `i` holds texture `textures[i]` (an index into the scene's).
    pub textures: Vec<usize>,
    /// Whether the textures are of several sizes, each bordered in its
    /// layer ([`bordered`]); else each fills its layer.
    pub bordered: bool,
}

/// The arrays of a scene's textures and where each texture lives.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TexturePlan {
    /// At most [`ARRAYS`]; none for a scene without textures.
    pub arrays: Vec<ArrayPlan>,
    /// Per texture of the scene.
    pub placements: Vec<Placement>,
    /// Per texture: its size as sampled ([`fitted_size`]).
    pub sizes: Vec<(u32, u32)>,
}

/// One group of textures while they are being joined.
struct Group {
    /// The largest width and height among the textures.
    width: u32,
    height: u32,
    /// Whether all textures have that size.
    uniform: bool,
    textures: Vec<usize>,
}

impl Group {
    fn new(textures: Vec<usize>, sizes: &[(u32, u32)]) -> Self {
        let width = textures.iter().map(|&t| sizes[t].0).max().unwrap_or(1);
        let height = textures.iter().map(|&t| sizes[t].1).max().unwrap_or(1);
        let uniform = textures.iter().all(|&t| sizes[t] == (width, height));
        Self {
            width,
            height,
            uniform,
            textures,
        }
    }
    /// The layer's size: the textures' own, or two larger for the border.
    fn layer(&self) -> (u32, u32) {
        match self.uniform {
            true => (self.width, self.height),
            false => (self.width + 2, self.height + 2),
        }
    }
    fn arrays(&self) -> usize {
        self.textures.len().div_ceil(MAX_LAYERS)
    }
    fn texels(&self) -> u64 {
        let (w, h) = self.layer();
        w as u64 * h as u64 * self.textures.len() as u64
    }
}

impl TexturePlan {
    /// The arrays for `textures`, or an error that names a texture whose
    /// pixels do not match its size, or says that the textures do not fit
    /// the arrays.
    pub fn new(textures: &[Texture]) -> Result<Self> {
        let own: u64 = textures
            .iter()
            .map(|t| {
                let (w, h) = fitted_size(t.width, t.height);
                w as u64 * h as u64
            })
            .sum();
        Self::with_padding(textures, own.max(PAD_TEXELS))
    }

    /// [`TexturePlan::new`], joining groups past [`ARRAYS`] while the
    /// texels padding adds stay within `padding`.
    pub fn with_padding(textures: &[Texture], padding: u64) -> Result<Self> {
        for t in textures {
            check_texture(t)?;
        }
        let most = ARRAYS * MAX_LAYERS;
        if textures.len() > most {
            bail!(
                "the scene has {} textures; isr samples at most {most} ({ARRAYS} texture arrays of \
                 {MAX_LAYERS} layers, what every Vulkan device supports)",
                textures.len()
            );
        }
        let sizes: Vec<(u32, u32)> = textures
            .iter()
            .map(|t| fitted_size(t.width, t.height))
            .collect();
        let mut by_size: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
        for (i, &s) in sizes.iter().enumerate() {
            by_size.entry(s).or_default().push(i);
        }
        if by_size.len() > EXACT_SIZES {
            // A texture too large for a border keeps its own size's group.
            let mut classes: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
            for (i, &(w, h)) in sizes.iter().enumerate() {
                let class = match can_border((w, h)) {
                    true => (w.next_power_of_two(), h.next_power_of_two()),
                    false => (w, h),
                };
                classes.entry(class).or_default().push(i);
            }
            by_size = classes;
        }
        let mut groups: Vec<Group> = by_size
            .into_values()
            .map(|textures| Group::new(textures, &sizes))
            .collect();
        while groups.iter().map(Group::arrays).sum::<usize>() > ARRAYS {
            let Some((i, j)) = cheapest_join(&groups) else {
                bail!(
                    "the scene's textures need more than {ARRAYS} texture arrays: textures of \
                     {} sizes, and one with a side over {} shares an array only with textures \
                     of its own size",
                    groups.len(),
                    MAX_SIDE - 2
                );
            };
            let b = groups.remove(j);
            let mut joined = std::mem::take(&mut groups[i].textures);
            joined.extend(b.textures);
            joined.sort_unstable();
            groups[i] = Group::new(joined, &sizes);
        }
        // Fewer arrays: a CPU driver samples every array of the shader's
        // choice for every fragment (see `PAD_TEXELS`).
        let own: u64 = sizes.iter().map(|&(w, h)| w as u64 * h as u64).sum();
        let allowed = (own + padding).min(Limits::DEFAULT.texture_pixels.max(own));
        while let Some((i, j)) = cheapest_join(&groups) {
            let (a, b) = (&groups[i], &groups[j]);
            let mut joined = a.textures.clone();
            joined.extend(&b.textures);
            joined.sort_unstable();
            let g = Group::new(joined, &sizes);
            let total: u64 = groups.iter().map(Group::texels).sum::<u64>() + g.texels()
                - a.texels()
                - b.texels();
            if g.arrays() >= a.arrays() + b.arrays() || total > allowed {
                break;
            }
            groups.remove(j);
            groups[i] = g;
        }
        let mut arrays = vec![];
        let mut placements = vec![
            Placement {
                array: u32::MAX,
                layer: 0
            };
            textures.len()
        ];
        for g in groups {
            let (width, height) = g.layer();
            for chunk in g.textures.chunks(MAX_LAYERS) {
                for (layer, &t) in chunk.iter().enumerate() {
                    placements[t] = Placement {
                        array: arrays.len() as u32,
                        layer: layer as u32,
                    };
                }
                arrays.push(ArrayPlan {
                    width,
                    height,
                    textures: chunk.to_vec(),
                    bordered: !g.uniform,
                });
            }
        }
        let plan = Self {
            arrays,
            placements,
            sizes,
        };
        // Joined groups pad small textures to the largest's layer: a few
        // percent for real scenes (Sponza 5.1%), but textures of many
        // shapes (long thin ones of both orientations) could ask for
        // thousands of times their own texels. The arrays are held to the
        // decode budget of all textures (`Limits::texture_pixels`), or to
        // the textures' own texels when a scene built in code has more.
        let budget = Limits::DEFAULT.texture_pixels.max(own);
        let planned = plan.bytes() / 4;
        if planned > budget {
            bail!(
                "the scene's {} textures have {own} texels, but grouped into {ARRAYS} texture                  arrays of one layer size each they would take {planned} texels, over the                  budget of {budget}: they have too many different shapes; resize them to a few                  sizes",
                textures.len()
            );
        }
        Ok(plan)
    }

    /// Bytes of GPU memory the arrays take (RGBA8, one mip), as the memory
    /// check counts them (`frame::check`).
    pub fn bytes(&self) -> u64 {
        self.arrays
            .iter()
            .map(|a| a.width as u64 * a.height as u64 * 4 * a.textures.len() as u64)
            .sum()
    }

    /// Texture `t`'s `(scale, offset)`: the shader samples its layer at
    /// `fract(uv) * scale + offset`. A texture that fills its layer is
    /// `(1, 0)`; a bordered one is `size / layer` and `1 / layer` (texel
    /// `(1, 1)` on).
    pub fn transform(&self, t: usize) -> ([f32; 2], [f32; 2]) {
        let a = &self.arrays[self.placements[t].array as usize];
        if !a.bordered {
            return ([1.0; 2], [0.0; 2]);
        }
        let (w, h) = self.sizes[t];
        let (lw, lh) = (a.width as f32, a.height as f32);
        ([w as f32 / lw, h as f32 / lh], [1.0 / lw, 1.0 / lh])
    }
}

/// Whether a texture of `size` fits a bordered layer.
fn can_border((w, h): (u32, u32)) -> bool {
    w + 2 <= MAX_SIDE && h + 2 <= MAX_SIDE
}

/// The pair of groups (`i < j`) to join next: of the joins that save an
/// array, the one that adds the fewest texels; if none saves one (groups of
/// many full arrays), the cheapest join of all, which leads to one that
/// does. Joins whose layer would pass [`MAX_SIDE`] are left out; `None` if
/// no join is left. With no texture too large for a border, joining all
/// groups into one always fits, as there are at most
/// `ARRAYS * MAX_LAYERS` textures.
fn cheapest_join(groups: &[Group]) -> Option<(usize, usize)> {
    let mut best: Option<(bool, u64, usize, usize)> = None;
    for i in 0..groups.len() {
        for j in i + 1..groups.len() {
            let (a, b) = (&groups[i], &groups[j]);
            let same = a.uniform && b.uniform && (a.width, a.height) == (b.width, b.height);
            let (w, h) = (a.width.max(b.width), a.height.max(b.height));
            if !same && !can_border((w, h)) {
                continue;
            }
            let n = a.textures.len() + b.textures.len();
            let layer = if same { (w, h) } else { (w + 2, h + 2) };
            let texels = layer.0 as u64 * layer.1 as u64 * n as u64;
            let added = texels - a.texels() - b.texels();
            let saves = n.div_ceil(MAX_LAYERS) < a.arrays() + b.arrays();
            let better = match best {
                None => true,
                Some((s, c, ..)) => (saves, std::cmp::Reverse(added)) > (s, std::cmp::Reverse(c)),
            };
            if better {
                best = Some((saves, added, i, j));
            }
        }
    }
    best.map(|(_, _, i, j)| (i, j))
}

/// A texture's pixels must be its size: a scene built by code could say
/// otherwise, and the upload would read past them.
fn check_texture(t: &Texture) -> Result<()> {
    let expected = t.width as u64 * t.height as u64 * 4;
    if t.width == 0 || t.height == 0 || t.rgba8.len() as u64 != expected {
        bail!(
            "texture {} is {}x{} but holds {} bytes; an RGBA8 texture of at least 1x1 holds \
             width x height x 4",
            t.name,
            t.width,
            t.height,
            t.rgba8.len()
        );
    }
    Ok(())
}

/// A texture's size as sampled: its own, or shrunk to a longest side of
/// [`MAX_SIDE`] keeping its aspect ratio (each side at least 1).
pub fn fitted_size(width: u32, height: u32) -> (u32, u32) {
    if width <= MAX_SIDE && height <= MAX_SIDE {
        return (width, height);
    }
    let long = width.max(height) as u64;
    let side = |s: u32| ((s as u64 * MAX_SIDE as u64 + long / 2) / long).max(1) as u32;
    (side(width), side(height))
}

/// The textures as sampled: each itself, or shrunk when larger than a layer
/// ([`fitted_size`]). The GPU upload and the path tracer both sample these.
/// A texture whose pixels do not match its size is passed on as it is
/// (the upload refuses it).
pub fn fitted(textures: &[Texture]) -> Vec<Cow<'_, Texture>> {
    textures
        .iter()
        .map(|t| {
            let (w, h) = fitted_size(t.width, t.height);
            if (w, h) == (t.width, t.height) || check_texture(t).is_err() {
                Cow::Borrowed(t)
            } else {
                Cow::Owned(shrink::shrink(t, w, h))
            }
        })
        .collect()
}

/// `t`'s texels (its pixels matching its size) ringed by a border of one
/// texel, each border texel a copy of the texel that repeat would read
/// there: the last column left of the first, the first right of the last,
/// likewise rows, and the opposite corners at the corners.
/// `(width + 2) x (height + 2)` RGBA8, rows top to bottom.
pub fn bordered(t: &Texture) -> Vec<u8> {
    let (w, h) = (t.width as usize, t.height as usize);
    let mut out = Vec::with_capacity((w + 2) * (h + 2) * 4);
    for y in 0..h + 2 {
        let row = &t.rgba8[(y + h - 1) % h * w * 4..][..w * 4];
        out.extend_from_slice(&row[(w - 1) * 4..]);
        out.extend_from_slice(row);
        out.extend_from_slice(&row[..4]);
    }
    out
}

/// What [`fitted`] will shrink, as one warning to print (none if nothing
/// is): the first few textures by name, then how many more.
pub fn warnings(textures: &[Texture]) -> Vec<String> {
    let shrunk: Vec<String> = textures
        .iter()
        .filter_map(|t| {
            let (w, h) = fitted_size(t.width, t.height);
            ((w, h) != (t.width, t.height))
                .then(|| format!("{} is {}x{}, shrunk to {w}x{h}", t.name, t.width, t.height))
        })
        .collect();
    if shrunk.is_empty() {
        return vec![];
    }
    const NAMED: usize = 3;
    let mut list = shrunk[..shrunk.len().min(NAMED)].join("; ");
    if shrunk.len() > NAMED {
        list += &format!("; and {} more", shrunk.len() - NAMED);
    }
    vec![format!(
        "texture layers are at most {MAX_SIDE}x{MAX_SIDE} on every device, so {} texture(s) \
         are shrunk to fit (averaged in linear light): texture {list}",
        shrunk.len()
    )]
}

#[cfg(test)]
mod tests;
