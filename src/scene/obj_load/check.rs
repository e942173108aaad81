//! Every line of an OBJ file, read and checked one at a time: [`Lines`]
//! reads a line of the source (at most `Limits::line_bytes`; lines end in
//! LF, CRLF or a lone CR; a byte-order mark before the first keyword is
//! dropped), [`line`] checks it and adds what it defines to the state:
//! positions, texture coordinates and normals as they come, and each face
//! fanned into triangles straight into the mesh of its material
//! (`super::assemble`), its distinct vertices counted against the budget as
//! they appear. So an error names its line, a budget stops the read at the
//! line that passes it (a file of 10^8 `v` lines is refused after
//! `vertices` of them, never read whole), and nothing is held per line,
//! per group or per material switch beyond the geometry itself.

use super::State;
use crate::scene::limits;
use crate::scene::text::quote;
use anyhow::{anyhow, bail, Result};
use glam::Vec3;
use std::io::BufRead;

/// The lines of a source, read one at a time.
pub(super) struct Lines<R> {
    src: R,
    raw: Vec<u8>,
    /// A line ended in CR: a LF right after it is the same line end.
    skip_lf: bool,
    first: bool,
    /// Bytes taken from the source (what a lazy source was asked for).
    pub bytes: u64,
}

impl<R: BufRead> Lines<R> {
    pub(super) fn new(src: R) -> Self {
        Self {
            src,
            raw: Vec::new(),
            skip_lf: false,
            first: true,
            bytes: 0,
        }
    }

    /// The next line without its end, or `None` at the end of the source.
    /// A line over `max` bytes is an error, found before it is held whole.
    pub(super) fn next(&mut self, max: u64) -> Result<Option<&[u8]>> {
        self.raw.clear();
        let mut any = false;
        loop {
            let buf = self
                .src
                .fill_buf()
                .map_err(|e| anyhow!("cannot read the file: {e}"))?;
            if buf.is_empty() {
                break;
            }
            if std::mem::take(&mut self.skip_lf) && buf[0] == b'\n' {
                self.src.consume(1);
                self.bytes += 1;
                continue;
            }
            any = true;
            let end = buf.iter().position(|&b| b == b'\n' || b == b'\r');
            let keep = end.unwrap_or(buf.len());
            if (self.raw.len() + keep) as u64 > max {
                bail!(
                    "the line is longer than {}, the limit for one line",
                    limits::bytes(max)
                );
            }
            self.raw.extend_from_slice(&buf[..keep]);
            let take = match end {
                Some(i) => {
                    self.skip_lf = buf[i] == b'\r';
                    i + 1
                }
                None => keep,
            };
            self.src.consume(take);
            self.bytes += take as u64;
            if end.is_some() {
                break;
            }
        }
        if !any {
            return Ok(None);
        }
        if std::mem::take(&mut self.first) && self.raw.starts_with(b"\xEF\xBB\xBF") {
            self.raw.drain(..3);
        }
        Ok(Some(&self.raw))
    }
}

/// Statements of the OBJ format isr does not render (free-form geometry,
/// lines, points, smoothing groups, display attributes): each is ignored,
/// with one warning for them all.
const IGNORED: &[(&str, &str)] = &[
    ("l", "line elements are not rendered"),
    ("p", "point elements are not rendered"),
    ("s", "smoothing groups are not read: normals the file lacks are computed with a 60 degree crease angle"),
    ("vp", "free-form geometry is not rendered"),
    ("cstype", "free-form geometry is not rendered"),
    ("deg", "free-form geometry is not rendered"),
    ("bmat", "free-form geometry is not rendered"),
    ("step", "free-form geometry is not rendered"),
    ("curv", "free-form geometry is not rendered"),
    ("curv2", "free-form geometry is not rendered"),
    ("surf", "free-form geometry is not rendered"),
    ("parm", "free-form geometry is not rendered"),
    ("trim", "free-form geometry is not rendered"),
    ("hole", "free-form geometry is not rendered"),
    ("scrv", "free-form geometry is not rendered"),
    ("sp", "free-form geometry is not rendered"),
    ("end", "free-form geometry is not rendered"),
    ("con", "free-form geometry is not rendered"),
    ("mg", "merging groups are not read"),
];

/// Checks one line (without its end of line) and adds what it defines.
pub(super) fn line(raw: &[u8], st: &mut State) -> Result<()> {
    let trimmed = raw.trim_ascii_start();
    if trimmed.is_empty() || trimmed[0] == b'#' {
        // Comments may be in any encoding.
        return Ok(());
    }
    let line = std::str::from_utf8(raw)
        .map_err(|e| anyhow!("the line is not UTF-8 text (byte {})", e.valid_up_to() + 1))?;
    let mut words = line.split_whitespace();
    let key = words.next().unwrap_or_default();
    let rest = line.trim_start()[key.len()..].trim();
    let limits = st.options.limits;
    match key {
        "v" => {
            let index = st.geometry.positions.len() + 1;
            let n: Vec<f32> = numbers(words, "vertex", index)?;
            let (x, y, z) = match n.len() {
                3 | 6 => (n[0], n[1], n[2]),
                4 => {
                    let w = n[3];
                    if w == 0.0 {
                        bail!("vertex {index} has the weight w = 0");
                    }
                    (n[0] / w, n[1] / w, n[2] / w)
                }
                k => bail!(
                    "a vertex is `v x y z`, `v x y z w` or `v x y z r g b`; this one has {k} number(s){}",
                    if k < 3 { " (is the line cut short?)" } else { "" }
                ),
            };
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                bail!("vertex {index} is at ({x}, {y}, {z}), not a finite position");
            }
            if index as u64 > limits.vertices {
                bail!(
                    "the file has more than {} vertex positions (v); the limit is {}",
                    limits.vertices,
                    limits.vertices
                );
            }
            st.geometry.positions.push([x, y, z]);
        }
        "vt" => {
            let index = st.geometry.texcoords.len() + 1;
            let n = numbers(words, "texture coordinate", index)?;
            if !(1..=3).contains(&n.len()) {
                bail!(
                    "a texture coordinate is `vt u [v [w]]`; this one has {} numbers",
                    n.len()
                );
            }
            let (u, v) = (n[0], n.get(1).copied().unwrap_or(0.0));
            if u.abs().max(v.abs()) > limits.texcoord {
                bail!(
                    "texture coordinate {index} is ({u:e}, {v:e}); isr supports texture coordinates up to {} (repeats of the texture): beyond, 32-bit floats keep too few bits for a texel",
                    limits.texcoord
                );
            }
            if index as u64 > limits.vertices {
                bail!(
                    "the file has more than {} texture coordinates (vt); the limit is {}",
                    limits.vertices,
                    limits.vertices
                );
            }
            st.geometry.texcoords.push([u, v]);
        }
        "vn" => {
            let index = st.geometry.normals.len() + 1;
            let n = numbers(words, "normal", index)?;
            if n.len() != 3 {
                bail!("a normal is `vn x y z`; this one has {} number(s)", n.len());
            }
            if index as u64 > limits.vertices {
                bail!(
                    "the file has more than {} normals (vn); the limit is {}",
                    limits.vertices,
                    limits.vertices
                );
            }
            let unit = crate::scene::direction(Vec3::new(n[0], n[1], n[2]));
            if unit.is_none() {
                let at = st.here();
                st.tally.zero_normals.add(|| at);
            }
            // A zero normal is kept as zero: faces using it get computed
            // normals.
            st.geometry
                .normals
                .push(unit.map_or([0.0; 3], |n| n.to_array()));
        }
        "f" => face(words, st)?,
        // Groups and objects do not split meshes (one mesh a material): a
        // file of a million `g` lines costs nothing more.
        "o" | "g" => {}
        "usemtl" => {
            if rest.is_empty() {
                bail!("usemtl names no material");
            }
            let found = st.materials.by_name.get(rest).copied();
            if found.is_none() {
                let at = st.here();
                st.tally.unknown_materials.add(rest, "", || at);
            }
            st.select(found);
        }
        "mtllib" => {
            if rest.is_empty() {
                bail!("mtllib names no file");
            }
            // Several names on a line, separated by spaces.
            for name in rest.split_whitespace() {
                super::mtl::load_library(st, name)
                    .map_err(|e| e.context(format!("mtllib {}", quote(name))))?;
            }
        }
        _ => {
            let why = IGNORED
                .iter()
                .find(|(k, _)| *k == key)
                .map_or("it is not part of the OBJ format isr reads", |(_, why)| why);
            let at = st.here();
            st.tally.ignored_statements.add(key, why, || at);
        }
    }
    Ok(())
}

/// A face: its corners checked one at a time and fanned into triangles
/// as they come (a face of 10^6 corners holds no list of them).
fn face<'a>(words: impl Iterator<Item = &'a str>, st: &mut State) -> Result<()> {
    let mut corners = 0u64;
    let mut first = [0u32; 3];
    let mut previous = [0u32; 3];
    let (mut with_normal, mut with_uv) = (0u64, 0u64);
    for word in words {
        let c = corner(word, st)?;
        corners += 1;
        with_normal += u64::from(c[2] != super::NONE);
        with_uv += u64::from(c[1] != super::NONE);
        match corners {
            1 => first = c,
            2 => {}
            _ => {
                st.triangles += 1;
                if st.triangles > st.options.limits.triangles {
                    bail!(
                        "the faces so far fan into more than {} triangles; the limit is {}",
                        st.options.limits.triangles,
                        st.options.limits.triangles
                    );
                }
                st.triangle([first, previous, c])?;
            }
        }
        previous = c;
    }
    if corners < 3 {
        bail!(
            "a face needs at least 3 vertices; this one has {corners}{}",
            if corners > 0 {
                " (is the line cut short?)"
            } else {
                ""
            }
        );
    }
    if with_normal > 0 && with_normal < corners {
        let at = st.here();
        st.tally.partial_normals.add(|| at);
    }
    if with_uv > 0 && with_uv < corners {
        let at = st.here();
        st.tally.partial_texcoords.add(|| at);
    }
    Ok(())
}

/// The numbers of a `v`, `vt` or `vn` line; a word that is not one is an
/// error naming the element.
fn numbers<'a>(words: impl Iterator<Item = &'a str>, what: &str, index: usize) -> Result<Vec<f32>> {
    let mut n = Vec::with_capacity(4);
    for w in words {
        if n.len() == 7 {
            bail!("{what} {index} has more numbers than any OBJ {what} has");
        }
        let x: f32 = w
            .parse()
            .map_err(|_| anyhow!("{what} {index}: '{}' is not a number", quote(w)))?;
        if !x.is_finite() {
            bail!(
                "{what} {index} has the coordinate '{}', which is {} in 32-bit floats: coordinates must be finite",
                quote(w),
                x
            );
        }
        n.push(x);
    }
    Ok(n)
}

/// The 0-based indices of one face corner (`v`, `v/vt`, `v//vn` or
/// `v/vt/vn`; [`super::NONE`] where it names none), each checked against
/// what the file defined above it: OBJ counts from 1, and `-k` is the k-th
/// last element defined so far.
fn corner(word: &str, st: &State) -> Result<[u32; 3]> {
    let mut parts = word.split('/');
    let mut out = [super::NONE; 3];
    let names = ["vertex", "texture coordinate", "normal"];
    let g = &st.geometry;
    let counts = [g.positions.len(), g.texcoords.len(), g.normals.len()].map(|n| n as u64);
    for k in 0..3 {
        let Some(p) = parts.next() else { break };
        if p.is_empty() {
            if k == 0 {
                bail!("face vertex '{}' has no position index", quote(word));
            }
            continue;
        }
        let i: i64 = p.parse().map_err(|_| {
            anyhow!(
                "face vertex '{}': '{}' is not an index",
                quote(word),
                quote(p)
            )
        })?;
        let n = counts[k];
        let abs = if i > 0 && (i as u64) <= n {
            i as u64
        } else if i < 0 && i.unsigned_abs() <= n {
            n + 1 - i.unsigned_abs()
        } else if i == 0 {
            bail!(
                "face vertex '{}' uses {} index 0; OBJ indices count from 1 (or back from -1)",
                quote(word),
                names[k]
            );
        } else {
            bail!(
                "face vertex '{}' refers to {} {i}, but {n} {} defined above the face",
                quote(word),
                names[k],
                if n == 1 { "is" } else { "are" }
            );
        };
        out[k] = u32::try_from(abs - 1)
            .ok()
            .filter(|&i| i != super::NONE)
            .ok_or_else(|| anyhow!("{} {i} is past the 32-bit indices isr uses", names[k]))?;
    }
    if parts.next().is_some() {
        bail!(
            "face vertex '{}' has more than three indices (v/vt/vn)",
            quote(word)
        );
    }
    Ok(out)
}
