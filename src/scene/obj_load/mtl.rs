//! MTL material libraries, read by isr (`newmtl`, `Kd`, `map_Kd`; every
//! other key is ignored with one warning per key) and handed to tobj for its
//! `usemtl` lookup; and the `map_Kd` textures (PNG or JPEG, sRGB), read
//! under the same policy and budgets as a glTF's images.

use super::check::short;
use super::{files, State};
use crate::scene::{limits, Texture};
use anyhow::{anyhow, bail, Context as _, Result};
use glam::Vec3;
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// A material as its library wrote it.
#[derive(Clone, Debug)]
pub(super) struct MtlMaterial {
    pub name: String,
    /// `Kd`, clamped to [0, 1]; `None` when the library gives none.
    pub kd: Option<Vec3>,
    /// `map_Kd`: the file name as written (options removed) and its line.
    pub map_kd: Option<(String, u64)>,
    /// The library, as the OBJ named it (for messages), and the folder its
    /// texture names are relative to (relative to the scene's folder where
    /// the library is inside it).
    pub library: String,
    pub folder: PathBuf,
}

/// One library, read once however often it is named.
#[derive(Clone)]
pub(super) struct Library {
    pub materials: Vec<MtlMaterial>,
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

/// tobj's material loader: reads library `name` (relative to the OBJ's
/// folder) and returns its materials for `usemtl`; a failure is recorded in
/// the state (the reader then stops tobj) with the OBJ's line that named it.
pub(super) fn load_library(state: &RefCell<State>, name: &Path) -> tobj::MTLLoadResult {
    let mut st = state.borrow_mut();
    if st.error.is_some() {
        return Err(tobj::LoadError::GenericFailure);
    }
    let name = name.to_string_lossy().into_owned();
    match read_library(&mut st, &name) {
        Ok(lib) => {
            let mut map = HashMap::new();
            let mut materials = Vec::new();
            for (i, m) in lib.materials.iter().enumerate() {
                map.insert(m.name.clone(), i);
                st.material_names.insert(m.name.clone());
                materials.push(tobj::Material {
                    name: m.name.clone(),
                    ..Default::default()
                });
            }
            // tobj appends each library's materials to its list: the same
            // order here, so its material ids index `st.materials`.
            st.materials.extend(lib.materials);
            Ok((materials, map))
        }
        Err(e) => {
            let e = e.context(format!(
                "{} line {}: mtllib {}",
                st.display,
                st.line,
                short(&name)
            ));
            st.error = Some(e);
            Err(tobj::LoadError::GenericFailure)
        }
    }
}

fn read_library(st: &mut State, name: &str) -> Result<Library> {
    let allow = st.options.allow_outside_uris;
    let path = files::resolve(name, Path::new(""), &st.base, allow)?;
    if let Some(lib) = st.libraries.get(&path) {
        return Ok(lib.clone());
    }
    let left = st
        .options
        .limits
        .material_library_bytes
        .saturating_sub(st.library_bytes);
    let bytes =
        crate::scene::uri::read_capped(&path, left, "the material library").with_context(|| {
            if st.library_bytes > 0 {
                format!(
                    "the material libraries may be {} in all, and {} are read already",
                    limits::bytes(st.options.limits.material_library_bytes),
                    limits::bytes(st.library_bytes)
                )
            } else {
                format!("reading {}", path.display())
            }
        })?;
    st.library_bytes += bytes.len() as u64;
    let folder = files::folder_of(name, Path::new(""));
    let lib = parse(&bytes, name, folder, st)?;
    st.libraries.insert(path, lib.clone());
    Ok(lib)
}

/// The materials of one library; `name` is how the OBJ named it.
fn parse(bytes: &[u8], name: &str, folder: PathBuf, st: &mut State) -> Result<Library> {
    let mut materials: Vec<MtlMaterial> = Vec::new();
    let max_line = st.options.limits.line_bytes;
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let n = i as u64 + 1;
        let at = || format!("{name} line {n}");
        if raw.len() as u64 > max_line {
            bail!(
                "{}: the line is longer than {}, the limit for one line",
                at(),
                limits::bytes(max_line)
            );
        }
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let trimmed = raw.trim_ascii_start();
        if trimmed.is_empty() || trimmed[0] == b'#' {
            continue;
        }
        let line = std::str::from_utf8(raw).map_err(|_| anyhow!("{}: not UTF-8 text", at()))?;
        let mut words = line.split_whitespace();
        let key = words.next().unwrap_or_default();
        let rest = line.trim_start()[key.len()..].trim();
        let current = |materials: &mut Vec<MtlMaterial>| -> Result<usize> {
            if materials.is_empty() {
                bail!("{}: {key} comes before any newmtl", at());
            }
            Ok(materials.len() - 1)
        };
        match key {
            "newmtl" => {
                if rest.is_empty() {
                    bail!("{}: newmtl names no material", at());
                }
                materials.push(MtlMaterial {
                    name: rest.to_string(),
                    kd: None,
                    map_kd: None,
                    library: name.to_string(),
                    folder: folder.clone(),
                });
            }
            "Kd" => {
                let m = current(&mut materials)?;
                let values: Vec<&str> = words.collect();
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
                            short(rest)
                        )
                    })?;
                let kd = match parsed[..] {
                    [g] => Vec3::splat(g),
                    [r, g, b] => Vec3::new(r, g, b),
                    _ => bail!(
                        "{}: Kd takes three numbers (`Kd r g b`, or one for grey); this one has {}{}",
                        at(),
                        parsed.len(),
                        if parsed.len() < 3 { " (is the line cut short?)" } else { "" }
                    ),
                };
                if !(kd.is_finite() && kd.min_element() >= 0.0) {
                    bail!("{}: Kd {kd} must be finite and non-negative", at());
                }
                if kd.max_element() > 1.0 {
                    st.warnings.push(format!(
                        "{}: Kd {kd} of material {} is above 1 (it would reflect more light than it receives); clamped to 1",
                        at(),
                        materials[m].name
                    ));
                }
                materials[m].kd = Some(kd.min(Vec3::ONE));
            }
            "map_Kd" => {
                let m = current(&mut materials)?;
                let words: Vec<&str> = rest.split_whitespace().collect();
                let mut k = 0;
                let mut options = Vec::new();
                while let Some(&(option, count)) = words
                    .get(k)
                    .and_then(|w| MAP_OPTIONS.iter().find(|(o, _)| o == w))
                {
                    options.push(option);
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
                let words = &words[k..];
                if words.is_empty() {
                    bail!("{}: map_Kd names no texture file", at());
                }
                if !options.is_empty() {
                    st.warnings.push(format!(
                        "{}: map_Kd options {} ignored (the texture is read as is)",
                        at(),
                        options.join(" ")
                    ));
                }
                materials[m].map_kd = Some((words.join(" "), n));
            }
            "mtllib" => {
                let e = st.ignored_mtl.entry("mtllib".into()).or_insert((
                    at(),
                    0,
                    "a material library includes no other files",
                ));
                e.1 += 1;
            }
            _ => {
                let e = st.ignored_mtl.entry(key.to_string()).or_insert((
                    at(),
                    0,
                    "isr renders a diffuse albedo only, Kd times map_Kd",
                ));
                e.1 += 1;
            }
        }
    }
    let mut seen = std::collections::HashSet::new();
    for m in &materials {
        if !seen.insert(&m.name) {
            st.warnings.push(format!(
                "{name}: material {} is defined more than once; the last definition is used",
                m.name
            ));
        }
    }
    Ok(Library { materials })
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
    let at = || format!("{} line {line}: map_Kd {}", m.library, short(file));
    let path = files::resolve(file, &m.folder, &st.base, st.options.allow_outside_uris)
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
    let label = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    crate::scene::texture_decode::decode_texture(&bytes, label, limits, &mut textures.pixels)
}
