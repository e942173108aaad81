//! Every line of an OBJ file, checked by isr before tobj parses it: the
//! reader tobj pulls from ([`Checked`]) reads one line of the source at a
//! time (at most `Limits::line_bytes`), checks it, counts what it adds
//! against the budgets, and hands tobj the line in a plain form (absolute
//! indices, three coordinates, comments and ignored statements as empty
//! lines). So an error names its line, a budget stops the read as soon as
//! it is passed (a file of 10^8 `v` lines is refused after `vertices` of
//! them, never read whole), and tobj never sees what it would misread: an
//! index of 0 (which wraps around in tobj), a face index out of range
//! (reported by tobj only when the object ends), positions with colours on
//! some lines only, `l` lines (which tobj reads as faces).

use super::State;
use anyhow::{anyhow, bail, Result};
use std::cell::RefCell;
use std::io::{BufRead, Read};

/// The reader tobj parses: the checked lines of `src`.
pub(super) struct Checked<'a, R> {
    src: R,
    raw: Vec<u8>,
    out: Vec<u8>,
    pos: usize,
    state: &'a RefCell<State>,
    /// Bytes taken from `src` (what a lazy source was asked for).
    pub(super) bytes: u64,
}

impl<'a, R: BufRead> Checked<'a, R> {
    pub(super) fn new(src: R, state: &'a RefCell<State>) -> Self {
        Self {
            src,
            raw: Vec::new(),
            out: Vec::new(),
            pos: 0,
            state,
            bytes: 0,
        }
    }

    /// The next line of the source into `raw` (without its end of line);
    /// false at the end of the file.
    fn next_line(&mut self, max: u64) -> Result<bool> {
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
            any = true;
            let (take, done) = match buf.iter().position(|&b| b == b'\n') {
                Some(i) => (i + 1, true),
                None => (buf.len(), false),
            };
            let keep = if done { take - 1 } else { take };
            if (self.raw.len() + keep) as u64 > max {
                bail!(
                    "the line is longer than {}, the limit for one line",
                    super::limits::bytes(max)
                );
            }
            self.raw.extend_from_slice(&buf[..keep]);
            self.src.consume(take);
            self.bytes += take as u64;
            if done {
                break;
            }
        }
        if self.raw.last() == Some(&b'\r') {
            self.raw.pop();
        }
        Ok(any)
    }
}

impl<R: BufRead> Read for Checked<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Checked<'_, R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        while self.pos == self.out.len() {
            // An error found earlier (here, or while a library was read)
            // ends tobj's read.
            if self.state.borrow().error.is_some() {
                return Err(std::io::Error::other("stopped by isr's check"));
            }
            self.out.clear();
            self.pos = 0;
            let max = {
                let mut st = self.state.borrow_mut();
                // The number of the line about to be read, for its errors.
                st.line += 1;
                st.options.limits.line_bytes
            };
            let result = match self.next_line(max) {
                Ok(false) => {
                    self.state.borrow_mut().line -= 1;
                    return Ok(&[]);
                }
                Ok(true) => check_line(&self.raw, &mut self.state.borrow_mut(), &mut self.out),
                Err(e) => Err(e),
            };
            if let Err(e) = result {
                let mut st = self.state.borrow_mut();
                let e = e.context(format!("{} line {}", st.display, st.line.max(1)));
                st.error = Some(e);
                return Err(std::io::Error::other("stopped by isr's check"));
            }
        }
        Ok(&self.out[self.pos..])
    }

    fn consume(&mut self, amt: usize) {
        self.pos = (self.pos + amt).min(self.out.len());
    }
}

/// Statements of the OBJ format isr does not render (free-form geometry,
/// lines, points, smoothing groups, display attributes): each is ignored,
/// with one warning per statement.
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

/// Checks one line (without its end of line) and writes what tobj is to
/// parse into `out` (always ending in a newline).
fn check_line(raw: &[u8], st: &mut State, out: &mut Vec<u8>) -> Result<()> {
    use std::io::Write as _;
    let trimmed = raw.trim_ascii_start();
    if trimmed.is_empty() || trimmed[0] == b'#' {
        // Comments may be in any encoding; tobj gets an empty line.
        out.push(b'\n');
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
            let n: Vec<f32> = numbers(words, "vertex", st.positions + 1)?;
            let (x, y, z) = match n.len() {
                3 | 6 => (n[0], n[1], n[2]),
                4 => {
                    let w = n[3];
                    if w == 0.0 {
                        bail!("vertex {} has the weight w = 0", st.positions + 1);
                    }
                    (n[0] / w, n[1] / w, n[2] / w)
                }
                k => bail!(
                    "a vertex is `v x y z`, `v x y z w` or `v x y z r g b`; this one has {k} number(s){}",
                    if k < 3 { " (is the line cut short?)" } else { "" }
                ),
            };
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                bail!(
                    "vertex {} is at ({x}, {y}, {z}), not a finite position",
                    st.positions + 1
                );
            }
            st.positions += 1;
            if st.positions > limits.vertices {
                bail!(
                    "the file has more than {} vertex positions (v); the limit is {}",
                    limits.vertices,
                    limits.vertices
                );
            }
            writeln!(out, "v {x} {y} {z}")?;
        }
        "vt" => {
            let n = numbers(words, "texture coordinate", st.texcoords + 1)?;
            if !(1..=3).contains(&n.len()) {
                bail!(
                    "a texture coordinate is `vt u [v [w]]`; this one has {} numbers",
                    n.len()
                );
            }
            st.texcoords += 1;
            if st.texcoords > limits.vertices {
                bail!(
                    "the file has more than {} texture coordinates (vt); the limit is {}",
                    limits.vertices,
                    limits.vertices
                );
            }
            writeln!(out, "vt {} {}", n[0], n.get(1).copied().unwrap_or(0.0))?;
        }
        "vn" => {
            let n = numbers(words, "normal", st.normals + 1)?;
            if n.len() != 3 {
                bail!("a normal is `vn x y z`; this one has {} number(s)", n.len());
            }
            st.normals += 1;
            if st.normals > limits.vertices {
                bail!(
                    "the file has more than {} normals (vn); the limit is {}",
                    limits.vertices,
                    limits.vertices
                );
            }
            writeln!(out, "vn {} {} {}", n[0], n[1], n[2])?;
        }
        "f" => {
            out.push(b'f');
            let mut corners = 0u64;
            for word in words {
                corners += 1;
                let [v, vt, vn] = corner(word, st)?;
                write!(out, " {}", v.unwrap_or_default())?;
                match (vt, vn) {
                    (None, None) => {}
                    (Some(t), None) => write!(out, "/{t}")?,
                    (None, Some(n)) => write!(out, "//{n}")?,
                    (Some(t), Some(n)) => write!(out, "/{t}/{n}")?,
                }
            }
            out.push(b'\n');
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
            st.triangles += corners - 2;
            if st.triangles > limits.triangles {
                bail!(
                    "the faces so far fan into {} triangles; the limit is {}",
                    st.triangles,
                    limits.triangles
                );
            }
        }
        "o" | "g" => writeln!(out, "{key} {rest}")?,
        "usemtl" => {
            if rest.is_empty() {
                bail!("usemtl names no material");
            }
            if !st.material_names.contains(rest) {
                let line = st.line;
                st.unknown_materials
                    .entry(rest.to_string())
                    .or_insert((line, 0))
                    .1 += 1;
            }
            writeln!(out, "usemtl {rest}")?;
        }
        "mtllib" => {
            if rest.is_empty() {
                bail!("mtllib names no file");
            }
            // Each name on a line of its own: tobj reads the rest of the
            // line as one name.
            for name in rest.split_whitespace() {
                writeln!(out, "mtllib {name}")?;
            }
        }
        _ => {
            let why = IGNORED
                .iter()
                .find(|(k, _)| *k == key)
                .map_or("it is not part of the OBJ format isr reads", |(_, why)| why);
            let line = st.line;
            st.ignored
                .entry(key.to_string())
                .or_insert((line, 0, why))
                .1 += 1;
            out.push(b'\n');
        }
    }
    Ok(())
}

/// The numbers of a `v`, `vt` or `vn` line; a word that is not one is an
/// error naming the element.
fn numbers<'a>(words: impl Iterator<Item = &'a str>, what: &str, index: u64) -> Result<Vec<f32>> {
    let mut n = Vec::with_capacity(4);
    for w in words {
        if n.len() == 7 {
            bail!("{what} {index} has more numbers than any OBJ {what} has");
        }
        let x: f32 = w
            .parse()
            .map_err(|_| anyhow!("{what} {index}: '{}' is not a number", short(w)))?;
        if !x.is_finite() {
            bail!(
                "{what} {index} has the coordinate '{}', which is {} in 32-bit floats: coordinates must be finite",
                short(w),
                x
            );
        }
        n.push(x);
    }
    Ok(n)
}

/// The absolute 1-based indices of one face corner (`v`, `v/vt`, `v//vn`
/// or `v/vt/vn`), each checked against what the file defined above it:
/// OBJ counts from 1, and `-k` is the k-th last element defined so far.
fn corner(word: &str, st: &State) -> Result<[Option<u64>; 3]> {
    let mut parts = word.split('/');
    let mut out = [None; 3];
    let names = ["vertex", "texture coordinate", "normal"];
    let counts = [st.positions, st.texcoords, st.normals];
    for k in 0..3 {
        let Some(p) = parts.next() else { break };
        if p.is_empty() {
            if k == 0 {
                bail!("face vertex '{}' has no position index", short(word));
            }
            continue;
        }
        let i: i64 = p.parse().map_err(|_| {
            anyhow!(
                "face vertex '{}': '{}' is not an index",
                short(word),
                short(p)
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
                short(word),
                names[k]
            );
        } else {
            bail!(
                "face vertex '{}' refers to {} {i}, but {n} {} defined above the face",
                short(word),
                names[k],
                if n == 1 { "is" } else { "are" }
            );
        };
        out[k] = Some(abs);
    }
    if parts.next().is_some() {
        bail!(
            "face vertex '{}' has more than three indices (v/vt/vn)",
            short(word)
        );
    }
    Ok(out)
}

/// `s` cut to 40 characters for messages.
pub(super) fn short(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}
