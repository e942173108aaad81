//! Decoding a texture within the loaders' budgets (`limits`), shared by the
//! glTF and OBJ loaders: the size from the header is checked before anything
//! is decoded, and the decoder itself is held to it should the header lie.

use super::{limits::Limits, Texture};
use anyhow::{anyhow, bail, Result};

/// `bytes` (PNG or JPEG) as an RGBA8 texture named `label`, adding its
/// pixels to `pixels` (all textures of the file so far), or an error naming
/// `label` and the limit it would pass.
pub(super) fn decode_texture(
    bytes: &[u8],
    label: String,
    limits: &Limits,
    pixels: &mut u64,
) -> Result<Texture> {
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| anyhow!("{label}: cannot read ({})", reason(&e.to_string())))
    };
    let (w, h) = reader()?.into_dimensions().map_err(|e| {
        anyhow!(
            "{label}: cannot decode ({}); PNG and JPEG are supported",
            reason(&e.to_string())
        )
    })?;
    let max = limits.texture_dimension;
    if w > max || h > max {
        bail!("{label} is {w}x{h} pixels; textures may be at most {max}x{max}");
    }
    let own = w as u64 * h as u64;
    let total = pixels.saturating_add(own);
    if total > limits.texture_pixels {
        bail!(
            "{label} is {w}x{h} = {own} pixels, which brings the textures to {total} pixels; the limit is {} pixels for all textures together",
            limits.texture_pixels
        );
    }
    *pixels = total;
    let mut reader = reader()?;
    let mut decode_limits = image::Limits::default();
    decode_limits.max_image_width = Some(w);
    decode_limits.max_image_height = Some(h);
    decode_limits.max_alloc = Some(own.saturating_mul(8).saturating_add(1 << 20));
    reader.limits(decode_limits);
    let decoded = reader
        .decode()
        .map_err(|e| {
            anyhow!(
                "{label}: cannot decode ({}); PNG and JPEG are supported",
                reason(&e.to_string())
            )
        })?
        .to_rgba8();
    Ok(Texture {
        name: label,
        width: decoded.width(),
        height: decoded.height(),
        rgba8: decoded.into_raw(),
    })
}

/// A decoder's message as a user reads it: the png crate writes a chunk's
/// type as a Rust debug dump (`ChunkType { type: IHDR, critical: true,
/// ... }`), which becomes `chunk IHDR`; the rest is escaped (a chunk type
/// is four bytes of the file) and cut short.
fn reason(message: &str) -> String {
    const DUMP: &str = "ChunkType { type: ";
    let mut out = String::new();
    let mut rest = message;
    while let Some(i) = rest.find(DUMP) {
        out.push_str(&rest[..i]);
        let after = &rest[i + DUMP.len()..];
        let kind = after.split(',').next().unwrap_or_default();
        out.push_str("chunk ");
        out.push_str(kind);
        rest = after.find('}').map_or("", |j| &after[j + 1..]);
        rest = rest.strip_prefix(" chunk").unwrap_or(rest);
    }
    out.push_str(rest);
    super::text::quote_at_most(out.trim_end_matches('.'), 200)
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_chunk_type_is_named_not_dumped() {
        let m = "Format error decoding Png: CRC error: expected 0x7c930929 have 0x26930929 while decoding ChunkType { type: IHDR, critical: true, private: false, reserved: false, safecopy: false } chunk.";
        assert_eq!(
            super::reason(m),
            "Format error decoding Png: CRC error: expected 0x7c930929 have 0x26930929 while decoding chunk IHDR"
        );
        let m = "Format error decoding Png: Unrecognized critical chunk: ChunkType { type: ID\u{1b}T, critical: true, private: false, reserved: false, safecopy: false }";
        assert_eq!(
            super::reason(m),
            "Format error decoding Png: Unrecognized critical chunk: chunk ID\\u{1b}T"
        );
    }
}
