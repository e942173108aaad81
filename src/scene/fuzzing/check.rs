//! The properties every load of a generated (or any) case must have.

use crate::scene::{limits::Limits, Scene};

/// What a loaded scene must be for the renderer to take it: indices and
/// materials in range, every number finite, coordinates within `limits`,
/// a light and camera that can render, and warnings that are few, short
/// and escaped.
pub fn check_scene(s: &Scene, limits: &Limits) -> Result<(), String> {
    if s.instances.is_empty() || s.bounds().is_none() {
        return Err("a scene without geometry".into());
    }
    for m in &s.meshes {
        let n = m.vertices.len();
        if m.indices.iter().any(|&i| i as usize >= n) || m.indices.len() % 3 != 0 {
            return Err(format!("mesh {} has bad indices", m.name));
        }
        if m.material >= s.materials.len() {
            return Err(format!("mesh {} has a bad material", m.name));
        }
        let finite = |a: &[f32]| a.iter().all(|c| c.is_finite());
        for v in &m.vertices {
            if !(finite(&v.position) && finite(&v.normal) && finite(&v.uv)) {
                return Err(format!("mesh {} has non-finite vertices", m.name));
            }
            if v.uv.iter().any(|c| c.abs() > limits.texcoord + 1.0) {
                return Err(format!(
                    "mesh {} has texture coordinates {:?}",
                    m.name, v.uv
                ));
            }
        }
    }
    if s.materials
        .iter()
        .any(|m| m.texture.is_some_and(|t| t >= s.textures.len()))
    {
        return Err("a material with a missing texture".into());
    }
    let state = s
        .pose_at(0.0)
        .map_err(|e| format!("the rest pose: {e:#}"))?;
    let c = &state.camera;
    if !(c.world_from_camera.is_finite()
        && c.znear > 0.0
        && crate::scene::check_yfov(c.yfov).is_ok())
    {
        return Err(format!("a camera that cannot render: {c:?}"));
    }
    for l in &state.lights {
        let reach = (s.origin + l.position.as_dvec3()).abs().max_element();
        if !(l.position.is_finite()
            && l.direction.is_normalized()
            && l.color.is_finite()
            && l.intensity.is_finite()
            && l.intensity >= 0.0
            && reach <= limits.coordinate as f64 * 4.0)
        {
            return Err(format!("a light that cannot render: {l:?}"));
        }
    }
    if s.warnings.len() > 24 {
        return Err(format!("{} warnings", s.warnings.len()));
    }
    for w in &s.warnings {
        check_message(w)?;
    }
    Ok(())
}

/// A message a loader gives: short, one line, no byte of the file raw
/// (`text::sanitize` would change nothing).
pub fn check_message(m: &str) -> Result<(), String> {
    if m.is_empty() {
        return Err("an empty message".into());
    }
    if m.chars().count() > 3 * crate::scene::text::MESSAGE_CHARS / 2 {
        return Err(format!("a message of {} bytes", m.len()));
    }
    if crate::scene::text::sanitize(m) != m {
        return Err(format!("a message with raw characters: {m:?}"));
    }
    Ok(())
}
