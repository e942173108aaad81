//! From bytes to a glTF document: the GLB header, the JSON checks made before
//! the gltf crate validates (which would otherwise panic on some files).

use super::*;

/// The document and the GLB binary chunk. A file that starts with the GLB
/// magic, or is named `.glb` and is not JSON, is held to the GLB header.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<(gltf::Document, Option<Vec<u8>>)> {
    let named_glb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let looks_json = text.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{');
    let bytes = if bytes.starts_with(b"glTF") {
        glb_body(bytes)?
    } else if named_glb && !looks_json {
        bail!("not a valid GLB file: it does not start with the GLB magic \"glTF\"");
    } else if !looks_json {
        bail!("not a valid glTF 2.0 file: it is neither JSON (which starts with '{{') nor GLB (which starts with \"glTF\")");
    } else {
        bytes
    };
    let invalid = |e| match e {
        gltf::Error::Binary(e) => anyhow!("not a valid GLB file: {e}"),
        e => anyhow!("not a valid glTF 2.0 file: {e}"),
    };
    // Validation after `check_json`: gltf-json's own validation indexes the
    // POSITION accessor before checking that it exists (a panic).
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(invalid)?;
    let gltf::Gltf { document, blob } = gltf;
    let root = document.into_json();
    check_json(&root)?;
    // Animation data the validation rejects gets a message naming the
    // animation and channel.
    let document = gltf::Document::from_json(root).map_err(|e| {
        crate::scene::animation::explain_invalid(bytes).unwrap_or_else(|| invalid(e))
    })?;
    Ok((document, blob))
}

/// The GLB header (magic, version 2, total length within the file): the gltf
/// crate checks only the magic. Returns the bytes the header covers.
pub(super) fn glb_body(bytes: &[u8]) -> Result<&[u8]> {
    let word = |i: usize| {
        bytes
            .get(i..i + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        bail!(
            "not a valid GLB file: {} bytes is shorter than the 12-byte GLB header",
            bytes.len()
        );
    };
    if version != 2 {
        bail!("not a valid GLB file: GLB version {version} is not supported (only 2)");
    }
    let length = length as usize;
    if length > bytes.len() {
        bail!(
            "not a valid GLB file: the header declares {length} bytes but the file has {} (truncated?)",
            bytes.len()
        );
    }
    if length < 20 {
        bail!(
            "not a valid GLB file: the header's length {length} leaves no room for the JSON chunk"
        );
    }
    Ok(&bytes[..length])
}

/// What `gltf`'s validation would panic on, or leaves to accessors that
/// would panic on it.
pub(super) fn check_json(root: &gltf::json::Root) -> Result<()> {
    use gltf::json::validation::Checked;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                if index.value() >= root.accessors.len() {
                    let name = match semantic {
                        Checked::Valid(s) => s.to_string(),
                        Checked::Invalid => "an attribute".into(),
                    };
                    bail!(
                        "mesh {m} primitive {p}: {name} names accessor {}, which does not exist",
                        index.value()
                    );
                }
            }
        }
    }
    for (i, c) in root.cameras.iter().enumerate() {
        let ok = match c.type_ {
            Checked::Valid(gltf::json::camera::Type::Perspective) => c.perspective.is_some(),
            Checked::Valid(gltf::json::camera::Type::Orthographic) => c.orthographic.is_some(),
            Checked::Invalid => false,
        };
        if !ok {
            bail!("camera {i}: its type has no matching perspective/orthographic object");
        }
    }
    let lights = root
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .map_or(&[][..], |l| &l.lights[..]);
    for (i, l) in lights.iter().enumerate() {
        use gltf::json::extensions::scene::khr_lights_punctual::Type;
        if matches!(l.type_, Checked::Valid(Type::Spot)) && l.spot.is_none() {
            bail!("light {i}: a spot light without its \"spot\" object");
        }
        if matches!(l.type_, Checked::Invalid) {
            bail!("light {i}: unknown light type");
        }
    }
    for (i, n) in root.nodes.iter().enumerate() {
        if let Some(l) = n
            .extensions
            .as_ref()
            .and_then(|e| e.khr_lights_punctual.as_ref())
        {
            if l.light.value() >= lights.len() {
                bail!(
                    "node {i} names light {}, which does not exist",
                    l.light.value()
                );
            }
        }
    }
    for (i, img) in root.images.iter().enumerate() {
        if img.buffer_view.is_some() && img.mime_type.is_none() {
            bail!("image {i}: an image in a buffer view needs a mimeType");
        }
        if img.buffer_view.is_none() && img.uri.is_none() {
            bail!("image {i}: neither a uri nor a bufferView");
        }
    }
    Ok(())
}
