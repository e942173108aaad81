//! The URI policy for buffers and images, and bounded file reads.
//!
//! A scene file comes from anywhere, so the files it names are confined to its
//! own folder: a relative URI is percent-decoded, its `.` and `..` resolved
//! without touching the file system (climbing above the folder is refused),
//! then the path is canonicalised (symbolic links resolved) and must still lie
//! inside the canonical folder. Absolute paths, `..` escapes, `file:` URIs and
//! links out of the folder are refused unless the user opts in
//! (`LoadOptions::allow_outside_uris`); other schemes are never fetched;
//! `data:` URIs are always fine. Only regular files are read (checked before
//! opening, so a FIFO cannot block and `/dev/zero` is never read), and never
//! more bytes than the caller's bound.

use super::limits;
use crate::scene::text;
use anyhow::{anyhow, bail, Result};
use base64::Engine as _;
use std::io::Read as _;
use std::path::{Component, Path, PathBuf};

/// How to allow what the policy refuses, appended to its errors.
const HOW_TO_ALLOW: &str =
    "isr reads only files inside the scene file's folder; pass --allow-outside-uris to allow this";

/// Where a URI's bytes come from.
pub enum Source {
    /// The decoded payload of a `data:` URI.
    Data(Vec<u8>),
    /// A file the policy allows.
    File(PathBuf),
}

/// Resolves `uri` against `base` (the scene file's folder) under the policy.
pub fn resolve(uri: &str, base: &Path, allow_outside: bool) -> Result<Source> {
    if let Some(scheme) = scheme(uri) {
        if scheme.eq_ignore_ascii_case("data") {
            return data_uri(&uri[5..]).map(Source::Data);
        }
        if !scheme.eq_ignore_ascii_case("file") {
            bail!("URI scheme {scheme}: isr reads only files next to the scene and data: URIs");
        }
        if !allow_outside {
            bail!("file: URIs are refused: {HOW_TO_ALLOW}");
        }
        // file:///abs/path or file:/abs/path; a host other than empty or
        // localhost would be another machine.
        let rest = &uri[5..];
        let path = match rest.strip_prefix("//") {
            Some(r) => {
                let slash = r.find('/').unwrap_or(r.len());
                let host = &r[..slash];
                if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
                    bail!("file URI with host {host}: only local files can be read");
                }
                &r[slash..]
            }
            None => rest,
        };
        let path = PathBuf::from(percent_decode(path)?);
        if !path.is_absolute() {
            bail!("file URI without an absolute path");
        }
        return Ok(Source::File(path));
    }
    let decoded = percent_decode(uri)?;
    let rel = Path::new(&decoded);
    if rel.has_root() || rel.is_absolute() {
        if !allow_outside {
            bail!("absolute paths are refused: {HOW_TO_ALLOW}");
        }
        return Ok(Source::File(rel.to_path_buf()));
    }
    // `..` resolved lexically first: the folder's own parent must not be
    // reachable even when the path does not exist.
    let mut normal = PathBuf::new();
    let mut depth = 0usize;
    let mut escapes = false;
    for c in rel.components() {
        match c {
            Component::Normal(part) => {
                normal.push(part);
                depth += 1;
            }
            Component::CurDir => {}
            Component::ParentDir if depth > 0 => {
                normal.pop();
                depth -= 1;
            }
            Component::ParentDir => escapes = true,
            Component::RootDir | Component::Prefix(_) => escapes = true,
        }
    }
    let base = if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base
    };
    if escapes {
        if !allow_outside {
            bail!("the path climbs out of the scene file's folder with '..': {HOW_TO_ALLOW}");
        }
        return Ok(Source::File(base.join(rel)));
    }
    let path = base.join(&normal);
    if allow_outside {
        return Ok(Source::File(path));
    }
    // Symbolic links: where the path really is must be inside where the
    // folder really is.
    let real = std::fs::canonicalize(&path)
        .map_err(|e| anyhow!("cannot read {}: {e}", text::path(&path)))?;
    let real_base = std::fs::canonicalize(base).map_err(|e| {
        anyhow!(
            "cannot resolve the scene's folder {}: {e}",
            text::path(&base)
        )
    })?;
    if !real.starts_with(&real_base) {
        bail!(
            "{} resolves (through a symbolic link) to outside the scene file's folder: {HOW_TO_ALLOW}",
            text::path(&path)
        );
    }
    Ok(Source::File(real))
}

/// The URI's scheme (RFC 3986: a letter, then letters, digits, `+`, `-` or
/// `.`, then `:`), if it has one. `C:\x` on Windows would read as scheme `C`
/// and is refused like any other.
fn scheme(uri: &str) -> Option<&str> {
    let colon = uri.find(':')?;
    let s = &uri[..colon];
    let mut chars = s.chars();
    let first = chars.next()?;
    (first.is_ascii_alphabetic()
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.')))
    .then_some(s)
}

/// The payload of a `data:` URI (everything after `data:`); base64 only.
fn data_uri(rest: &str) -> Result<Vec<u8>> {
    let (header, payload) = rest
        .split_once(',')
        .ok_or_else(|| anyhow!("malformed data URI (no comma)"))?;
    if !header.ends_with(";base64") {
        bail!("only base64 data URIs are supported");
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload.trim())
        .map_err(|e| anyhow!("malformed base64 in data URI: {e}"))
}

/// `%XX` escapes decoded; the result must be UTF-8 without NUL.
pub fn percent_decode(s: &str) -> Result<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = |b: u8| (b as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    if out.contains(&0) {
        bail!("the URI contains a NUL byte (%00)");
    }
    String::from_utf8(out).map_err(|_| anyhow!("the URI is not UTF-8 once percent-decoded"))
}

/// What a file is, for "not a regular file" messages.
pub(super) fn kind(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

/// Opens `path` if it is a regular file, checked before opening (opening a
/// FIFO for reading blocks until a writer comes), and again on the handle.
/// Returns the file and its length.
fn open_regular(path: &Path) -> Result<(std::fs::File, u64)> {
    let meta =
        std::fs::metadata(path).map_err(|e| anyhow!("cannot read {}: {e}", text::path(&path)))?;
    if !meta.is_file() {
        bail!(
            "{} is {}: only regular files are read",
            text::path(&path),
            kind(meta.file_type())
        );
    }
    let file =
        std::fs::File::open(path).map_err(|e| anyhow!("cannot read {}: {e}", text::path(&path)))?;
    let meta = file
        .metadata()
        .map_err(|e| anyhow!("cannot read {}: {e}", text::path(&path)))?;
    if !meta.is_file() {
        bail!(
            "{} is {}: only regular files are read",
            text::path(&path),
            kind(meta.file_type())
        );
    }
    Ok((file, meta.len()))
}

/// Exactly the first `len` bytes of a regular file; an error, before reading,
/// if it is shorter (`truncated` names what it is, for the message).
pub fn read_prefix(path: &Path, len: u64, what: &str) -> Result<Vec<u8>> {
    let (file, size) = open_regular(path)?;
    if size < len {
        bail!("{what} has {size} bytes but the file declares byteLength {len}: the buffer is truncated");
    }
    let mut data = Vec::with_capacity(len as usize);
    file.take(len)
        .read_to_end(&mut data)
        .map_err(|e| anyhow!("cannot read {}: {e}", text::path(&path)))?;
    if (data.len() as u64) < len {
        bail!(
            "{what} has {} bytes but the file declares byteLength {len}: the buffer is truncated",
            data.len()
        );
    }
    Ok(data)
}

/// A whole regular file of at most `max` bytes (checked before reading).
pub fn read_capped(path: &Path, max: u64, what: &str) -> Result<Vec<u8>> {
    let (file, size) = open_regular(path)?;
    let too_big = |n: u64| {
        anyhow!(
            "{what} is {}, more than the limit of {}",
            limits::bytes(n),
            limits::bytes(max)
        )
    };
    if size > max {
        return Err(too_big(size));
    }
    let mut data = Vec::with_capacity(size as usize);
    // One byte more than allowed tells a file that grew after the check.
    file.take(max + 1)
        .read_to_end(&mut data)
        .map_err(|e| anyhow!("cannot read {}: {e}", text::path(&path)))?;
    if data.len() as u64 > max {
        return Err(too_big(data.len() as u64));
    }
    Ok(data)
}
