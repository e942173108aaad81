//! MTL material libraries, read by isr (`newmtl`, `Kd`, `map_Kd`; every
//! other key is ignored, with one warning for them all), each library once
//! however often the OBJ names it; and the `map_Kd` textures (PNG or JPEG,
//! sRGB), read under the same policy and budgets as a glTF's images.
//!
//! Memory: a library is read whole (within `material_library_bytes` for
//! all of them together), then each material keeps its name, `Kd` and
//! `map_Kd` (a few words beside the bytes of the names), and there are at
//! most `Limits::materials` of them.

use super::{files, State};
use crate::scene::text::{quote, strip_bom};
use crate::scene::{limits, Texture};
use anyhow::{anyhow, bail, Context as _, Result};
use glam::Vec3;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// A material as its library wrote it.
pub(super) struct MtlMaterial {
    pub name: Box<str>,
    /// `Kd`, clamped to [0, 1]; `None` when the library gives none.
    pub kd: Option<Vec3>,
    /// `map_Kd`: the file name as written (options removed) and its line.
    pub map_kd: Option<(Box<str>, u64)>,
    /// Its library, an index into [`Materials::libraries`].
    pub library: u32,
}

/// A library read: how the OBJ named it (for messages) and the folder its
/// texture names are relative to (relative to the scene's folder where the
/// library is inside it).
pub(super) struct Library {
    pub name: String,
    pub folder: PathBuf,
}

/// Every material of every library the OBJ named, in the order defined.
#[derive(Default)]
pub(super) struct Materials {
    pub list: Vec<MtlMaterial>,
    /// For `usemtl`: the latest definition of each name.
    pub by_name: HashMap<Box<str>, u32>,
    pub libraries: Vec<Library>,
    /// Libraries read, by resolved path: a library named again adds nothing.
    read: HashSet<PathBuf>,
    /// Names `mtllib` gave already (a line naming one library 20,000 times
    /// resolves it once).
    named: HashSet<String>,
    /// Bytes of the libraries read, against `material_library_bytes`.
    bytes: u64,
}

/// `map_Kd` options and how many values each takes (the MTL specification's
/// texture map options); the file name is what follows them.
const MAP_OPTIONS: &[(&str, usize)] = &[
    ("-blendu", 1),
    ("-blendv", 1),
    ("-boost", 1),
    ("-cc", 1),
    ("-clamp", 1),
    ("-imfchan", 1),
    ("-mm", 2),
    ("-o", 3),
    ("-s", 3),
    ("-t", 3),
    ("-texres", 1),
    ("-bm", 1),
];

/// Reads library `name` (relative to the OBJ's folder) unless it was read
/// already, adding its materials for the `usemtl` lines that follow.
pub(super) fn load_library(st: &mut State, name: &str) -> Result<()> {
    if st.materials.named.contains(name) {
        return Ok(());
    }
    let allow = st.options.allow_outside_uris;
    let path = files::resolve(name, Path::new(""), &st.base, allow)?;
    st.materials.named.insert(name.to_string());
    if !st.materials.read.insert(path.clone()) {
        return Ok(());
    }
    let limit = st.options.limits.material_library_bytes;
    let left = limit.saturating_sub(st.materials.bytes);
    let bytes =
        crate::scene::uri::read_capped(&path, left, "the material library").with_context(|| {
            if st.materials.bytes > 0 {
                format!(
                    "the material libraries may be {} in all, and {} are read already",
                    limits::bytes(limit),
                    limits::bytes(st.materials.bytes)
                )
            } else {
                format!("reading {}", path.display())
            }
        })?;
    st.materials.bytes += bytes.len() as u64;
    let library = st.materials.libraries.len() as u32;
    st.materials.libraries.push(Library {
        name: quote(name),
        folder: files::folder_of(name, Path::new("")),
    });
    parse(&bytes, library, st)
}

/// The lines of `bytes`, ended by LF, CRLF or a lone CR.
fn lines(bytes: &[u8]) -> impl Iterator<Item = &[u8]> {
    let mut rest = bytes;
    let mut done = bytes.is_empty();
    std::iter::from_fn(move || {
        if done {
            return None;
        }
        match rest.iter().position(|&b| b == b'\n' || b == b'\r') {
            Some(i) => {
                let line = &rest[..i];
                let skip = if rest[i] == b'\r' && rest.get(i + 1) == Some(&b'\n') {
                    2
                } else {
                    1
                };
                rest = &rest[i + skip..];
                done = rest.is_empty();
                Some(line)
            }
            None => {
                done = true;
                Some(rest)
            }
        }
    })
}

/// The materials of library number `library`.
fn parse(bytes: &[u8], library: u32, st: &mut State) -> Result<()> {
    let max_line = st.options.limits.line_bytes;
    let max_materials = st.options.limits.materials;
    let name = st.materials.libraries[library as usize].name.clone();
    // Names defined by this library so far, for the duplicate warning.
    let mut defined: HashSet<Box<str>> = HashSet::new();
    let mut current: Option<u32> = None;
    for (i, raw) in lines(strip_bom(bytes)).enumerate() {
        let n = i as u64 + 1;
        let at = || format!("{name} line {n}");
        if raw.len() as u64 > max_line {
            bail!(
                "{}: the line is longer than {}, the limit for one line",
                at(),
                limits::bytes(max_line)
            );
        }
        let trimmed = raw.trim_ascii_start();
        if trimmed.is_empty() || trimmed[0] == b'#' {
            continue;
        }
        let line = std::str::from_utf8(raw).map_err(|e| {
            anyhow!(
                "{}: the line is not UTF-8 text (byte {})",
                at(),
                e.valid_up_to() + 1
            )
        })?;
        let mut words = line.split_whitespace();
        let key = words.next().unwrap_or_default();
        let rest = line.trim_start()[key.len()..].trim();
        let current_material = |current: Option<u32>| -> Result<usize> {
            current
                .map(|m| m as usize)
                .ok_or_else(|| anyhow!("{}: {} comes before any newmtl", at(), quote(key)))
        };
        let materials = &mut st.materials;
        match key {
            "newmtl" => {
                if rest.is_empty() {
                    bail!("{}: newmtl names no material", at());
                }
                if materials.list.len() as u64 >= max_materials {
                    bail!(
                        "{}: the material libraries define more than {max_materials} materials; the limit is {max_materials}",
                        at()
                    );
                }
                let id = materials.list.len() as u32;
                let rest: Box<str> = rest.into();
                if !defined.insert(rest.clone()) {
                    st.tally
                        .duplicate_materials
                        .add(|| format!("{}: newmtl {}", at(), quote(&rest)));
                }
                materials.by_name.insert(rest.clone(), id);
                materials.list.push(MtlMaterial {
                    name: rest,
                    kd: None,
                    map_kd: None,
                    library,
                });
                current = Some(id);
            }
            "Kd" => {
                let m = current_material(current)?;
                let values: Vec<&str> = words.take(4).collect();
                if values.first() == Some(&"spectral") || values.first() == Some(&"xyz") {
                    bail!(
                        "{}: Kd {} is not supported; give the albedo as `Kd r g b`",
                        at(),
                        values[0]
                    );
                }
                let parsed: Vec<f32> = values
                    .iter()
                    .map(|w| w.parse::<f32>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| {
                        anyhow!(
                            "{}: Kd takes numbers (`Kd r g b`), got '{}'",
                            at(),
                            quote(rest)
                        )
                    })?;
                let kd = match parsed[..] {
                    [g] => Vec3::splat(g),
                    [r, g, b] => Vec3::new(r, g, b),
                    _ => bail!(
                        "{}: Kd takes three numbers (`Kd r g b`, or one for grey); this one has {}{}",
                        at(),
                        if parsed.len() > 3 { "more".to_string() } else { parsed.len().to_string() },
                        if parsed.len() < 3 { " (is the line cut short?)" } else { "" }
                    ),
                };
                if !(kd.is_finite() && kd.min_element() >= 0.0) {
                    bail!("{}: Kd {kd} must be finite and non-negative", at());
                }
                if kd.max_element() > 1.0 {
                    let material = &materials.list[m].name;
                    st.tally
                        .kd_above_one
                        .add(|| format!("{}: Kd {kd} of material {}", at(), quote(material)));
                }
                materials.list[m].kd = Some(kd.min(Vec3::ONE));
            }
            "map_Kd" => {
                let m = current_material(current)?;
                let words: Vec<&str> = rest.split_whitespace().collect();
                let mut k = 0;
                let mut options = false;
                while let Some(&(_, count)) = words
                    .get(k)
                    .and_then(|w| MAP_OPTIONS.iter().find(|(o, _)| o == w))
                {
                    options = true;
                    k += 1;
                    // -o, -s and -t take one to three numbers, -mm two;
                    // the others one word. The file name is what is left.
                    let mut taken = 0;
                    while taken < count
                        && k + 1 < words.len()
                        && (count == 1 || words[k].parse::<f32>().is_ok())
                    {
                        k += 1;
                        taken += 1;
                    }
                }
                let file = &words[k..];
                if file.is_empty() {
                    bail!("{}: map_Kd names no texture file", at());
                }
                if options {
                    let options = words[..k].join(" ");
                    st.tally
                        .map_options
                        .add(|| format!("{}: map_Kd {}", at(), quote(&options)));
                }
                materials.list[m].map_kd = Some((file.join(" ").into(), n));
            }
            "mtllib" => {
                st.tally.ignored_keys.add(
                    "mtllib",
                    "a material library includes no other files",
                    at,
                );
            }
            _ => {
                st.tally.ignored_keys.add(
                    key,
                    "isr renders a diffuse albedo only, Kd times map_Kd",
                    at,
                );
            }
        }
    }
    Ok(())
}

/// Decoded textures, each file once, with the pixel budget counted from the
/// headers before anything is decoded.
#[derive(Default)]
pub(super) struct Textures {
    pub ids: HashMap<PathBuf, usize>,
    pub pixels: u64,
}

/// The texture of `m`'s `map_Kd`, added to `scene` (once per file); its
/// index. A missing or undecodable texture is an error naming the library
/// and its line.
pub(super) fn texture(
    m: &MtlMaterial,
    st: &State,
    textures: &mut Textures,
    scene: &mut crate::scene::Scene,
) -> Result<Option<usize>> {
    let Some((file, line)) = &m.map_kd else {
        return Ok(None);
    };
    let library = &st.materials.libraries[m.library as usize];
    let at = || format!("{} line {line}: map_Kd {}", library.name, quote(file));
    let path = files::resolve(
        file,
        &library.folder,
        &st.base,
        st.options.allow_outside_uris,
    )
    .with_context(at)?;
    if let Some(&t) = textures.ids.get(&path) {
        return Ok(Some(t));
    }
    let t = decode(&path, &st.options.limits, textures).with_context(at)?;
    scene.textures.push(t);
    textures.ids.insert(path, scene.textures.len() - 1);
    Ok(Some(scene.textures.len() - 1))
}

fn decode(path: &Path, limits: &limits::Limits, textures: &mut Textures) -> Result<Texture> {
    let bytes = crate::scene::uri::read_capped(path, limits.image_file_bytes, "the image file")?;
    let name = path.file_name().map_or_else(
        || crate::scene::text::path(path),
        |n| quote(&n.to_string_lossy()),
    );
    // The message's context names the file already ("map_Kd t.png").
    let mut t = crate::scene::texture_decode::decode_texture(
        &bytes,
        "the texture".into(),
        limits,
        &mut textures.pixels,
    )?;
    t.name = name;
    Ok(t)
}
