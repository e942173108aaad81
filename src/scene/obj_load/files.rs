//! The files an OBJ names (its MTL libraries, their textures) under the
//! scene folder's policy (`super::super::uri`), and the OBJ file itself
//! opened for reading line by line.

use super::super::uri;
use crate::scene::text;
use anyhow::{anyhow, bail, Result};
use std::path::{Path, PathBuf};

/// Where `name` (a file name as an OBJ or MTL writes it, relative to `dir`,
/// a folder inside `base` given relative to it) is, under the policy for
/// `base` (the scene file's folder): inside it, or anywhere with
/// `allow_outside`. OBJ names are file names, not URIs: `%` and `:` mean
/// themselves, and a backslash (Windows exports) separates folders.
pub(in crate::scene) fn resolve(
    name: &str,
    dir: &Path,
    base: &Path,
    allow_outside: bool,
) -> Result<PathBuf> {
    let name = name.replace('\\', "/");
    if name.is_empty() {
        bail!("no file name is given");
    }
    let path = Path::new(&name);
    if path.is_absolute() {
        if !allow_outside {
            bail!(
                "{} is an absolute path: isr reads only files inside the scene file's folder; \
                 pass --allow-outside-uris to allow this",
                crate::scene::text::quote(&name)
            );
        }
        return Ok(path.to_path_buf());
    }
    if dir.is_absolute() {
        // Only with --allow-outside-uris: a library found outside the folder.
        return Ok(dir.join(path));
    }
    // `uri::resolve` applies the policy (lexical `..`, then symbolic links
    // through the canonical folders); as a URI the name is escaped so that
    // it means the same file: `%` as `%25`, and `./` first so that `c:x` has
    // no scheme.
    let relative = dir.join(path);
    let escaped = format!("./{}", relative.to_string_lossy().replace('%', "%25"));
    match uri::resolve(&escaped, base, allow_outside)? {
        uri::Source::File(p) => Ok(p),
        uri::Source::Data(_) => unreachable!("a path starting with ./ has no scheme"),
    }
}

/// The folder of `name` (resolved as [`resolve`] would), relative to the
/// scene's folder where it is inside it, for names found in that file.
pub(in crate::scene) fn folder_of(name: &str, dir: &Path) -> PathBuf {
    let name = name.replace('\\', "/");
    let parent = Path::new(&name).parent().unwrap_or(Path::new(""));
    if parent.is_absolute() {
        parent.to_path_buf()
    } else {
        dir.join(parent)
    }
}

/// Opens `path` if it is a regular file of at most `max` bytes, checked
/// before opening (a FIFO would block the open) and again on the handle, as
/// `uri` does for buffers. Returns the file and its length.
pub(in crate::scene) fn open_regular(path: &Path, max: u64) -> Result<(std::fs::File, u64)> {
    let check = |meta: &std::fs::Metadata| -> Result<()> {
        if !meta.is_file() {
            bail!(
                "{} is {}: only regular files are read",
                text::path(&path),
                uri::kind(meta.file_type())
            );
        }
        if meta.len() > max {
            bail!(
                "{} is {}, more than the limit of {}",
                text::path(&path),
                super::limits::bytes(meta.len()),
                super::limits::bytes(max)
            );
        }
        Ok(())
    };
    let meta =
        std::fs::metadata(path).map_err(|e| anyhow!("cannot read {}: {e}", text::path(&path)))?;
    check(&meta)?;
    let file =
        std::fs::File::open(path).map_err(|e| anyhow!("cannot read {}: {e}", text::path(&path)))?;
    let meta = file
        .metadata()
        .map_err(|e| anyhow!("cannot read {}: {e}", text::path(&path)))?;
    check(&meta)?;
    Ok((file, meta.len()))
}
