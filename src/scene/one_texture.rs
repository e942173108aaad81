//! Scenes for a device that cannot index an array of textures by a value
//! computed in the shader (`shaderSampledImageArrayDynamicIndexing`, which
//! lavapipe in Mesa 22 lacks): the renderer binds all textures as one array
//! and picks a material's by its index, so such a device takes at most one
//! texture (`frame::scene_gpu`). The archive scenes have more (Sponza 10,
//! Sibenik 5): [`keep_one`] keeps the texture that covers the most
//! triangles and gives every other textured material its texture's mean
//! colour times its own, so that the scene still renders, with the same
//! mean albedo, and says so in a warning. Every method of a run sees the
//! same scene, so comparisons between them hold; the images differ from a
//! device that indexes textures in the textures' detail only.

use super::Scene;
use glam::Vec3;

/// Reduces `scene` to at most one texture (see the module); returns the
/// warning to print, or `None` when it had at most one.
pub fn keep_one(scene: &mut Scene) -> Option<String> {
    if scene.textures.len() <= 1 {
        return None;
    }
    let mut use_count = vec![0usize; scene.textures.len()];
    for inst in &scene.instances {
        let mesh = &scene.meshes[inst.mesh];
        if let Some(t) = scene.materials[mesh.material].texture {
            use_count[t] += mesh.indices.len() / 3;
        }
    }
    // The most used; the first of equals.
    let keep = (0..use_count.len())
        .max_by_key(|&t| (use_count[t], std::cmp::Reverse(t)))
        .unwrap_or(0);
    let means: Vec<Vec3> = scene.textures.iter().map(mean_linear).collect();
    for m in &mut scene.materials {
        match m.texture {
            Some(t) if t == keep => m.texture = Some(0),
            Some(t) => {
                let c = m.base_color.truncate() * means[t];
                m.base_color = c.extend(m.base_color.w);
                m.texture = None;
            }
            None => {}
        }
    }
    let removed = scene.textures.len() - 1;
    let kept = scene.textures.swap_remove(keep);
    scene.textures = vec![kept];
    Some(format!(
        "this device cannot index an array of textures (shaderSampledImageArrayDynamicIndexing): \
         texture {} is kept, and the {removed} other(s) are replaced by their mean colour",
        scene.textures[0].name
    ))
}

/// The mean of a texture's texels, decoded from sRGB to linear.
pub fn mean_linear(t: &super::Texture) -> Vec3 {
    let lut: Vec<f32> = (0..256)
        .map(|c| {
            let c = c as f32 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        })
        .collect();
    let mut sum = glam::DVec3::ZERO;
    for px in t.rgba8.chunks_exact(4) {
        sum += glam::DVec3::new(
            lut[px[0] as usize] as f64,
            lut[px[1] as usize] as f64,
            lut[px[2] as usize] as f64,
        );
    }
    let n = (t.rgba8.len() / 4).max(1) as f64;
    (sum / n).as_vec3()
}
