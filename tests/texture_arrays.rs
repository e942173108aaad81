//! Textures of many sizes in the texture arrays (`frame::texture_arrays`):
//! each textured square shows its own texture, texel for texel, where the
//! G-buffer and the path tracer see it, on every device (lavapipe in Mesa 22
//! cannot index an array of descriptors, which the arrays do not need).
mod common;

use common::*;
use glam::{Vec2, Vec3};
use isr::frame::texture_arrays::{self, ARRAYS};
use isr::renderer::Renderer;
use isr::scene::{Scene, Texture};

/// Texture coordinates run from `UV_START` to `UV_START + UV_SPAN` across a
/// square, so that every texture repeats and wraps inside the square.
const UV_START: f32 = -0.3;
const UV_SPAN: f32 = 2.0;
/// Half the side of a square; squares are 1 m apart.
const HALF: f32 = 0.4;

/// Texels of random colours (sRGB 40 to 215 a channel), different for each
/// `seed`, so that a wrong texel or a wrong texture shows.
fn random_texture(name: &str, width: u32, height: u32, seed: u64) -> Texture {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut rgba8 = Vec::with_capacity(width as usize * height as usize * 4);
    for _ in 0..width * height {
        for _ in 0..3 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            rgba8.push(40 + (state % 176) as u8);
        }
        rgba8.push(255);
    }
    Texture {
        name: name.into(),
        width,
        height,
        rgba8,
    }
}

/// Sizes with more distinct ones than there are arrays (so that smaller
/// textures share larger layers), two of one size, a single texel, and one
/// wider than a layer (shrunk to 4096x3).
const SIZES: [(u32, u32); 13] = [
    (3, 5),
    (16, 16),
    (16, 16),
    (64, 32),
    (7, 300),
    (300, 7),
    (129, 65),
    (33, 250),
    (250, 33),
    (100, 100),
    (1, 1),
    (2, 9),
    (4100, 3),
];

/// The centre of square `i` on a 4 x 4 grid around the origin.
fn centre(i: usize) -> Vec3 {
    Vec3::new((i % 4) as f32 - 1.5, 0.0, (i / 4) as f32 - 1.5)
}

/// A white square a texture, seen from above.
fn squares() -> Scene {
    let mut s = Scene::empty(
        "texture arrays",
        sun(Vec3::new(0.2, -1.0, 0.1), 2.0),
        looking_down(),
    );
    for (i, &(w, h)) in SIZES.iter().enumerate() {
        s.textures
            .push(random_texture(&format!("{w}x{h} #{i}"), w, h, i as u64 + 1));
        let m = s.add_material(&format!("textured {i}"), Vec3::ONE);
        s.materials[m].texture = Some(i);
        s.add_quad(&format!("square {i}"), square(centre(i), HALF), m);
        for v in &mut s.meshes.last_mut().unwrap().vertices {
            v.uv = uv_at(i, Vec3::from(v.position)).to_array();
        }
    }
    s
}

/// The texture coordinates of world point `p` on square `i`.
fn uv_at(i: usize, p: Vec3) -> Vec2 {
    let local = (p - centre(i)) / (2.0 * HALF) + 0.5;
    Vec2::new(local.x, local.z) * UV_SPAN + UV_START
}

/// The square under world point `p`, away from its edges (where a pixel
/// may mix two squares or the background).
fn square_under(p: Vec3) -> Option<usize> {
    (0..SIZES.len()).find(|&i| {
        let d = (p - centre(i)).abs();
        p.y.abs() < 1e-3 && d.x < HALF - 0.02 && d.z < HALF - 0.02
    })
}

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Bilinear with repeat on linear values, texel centres at (i + 0.5) / size
/// (docs/algorithm.md section 3, step 1), written out here.
fn bilinear(t: &Texture, uv: Vec2) -> Vec3 {
    let (w, h) = (t.width as i64, t.height as i64);
    let x = uv.x * t.width as f32 - 0.5;
    let y = uv.y * t.height as f32 - 0.5;
    let (fx, fy) = (x - x.floor(), y - y.floor());
    let texel = |i: i64, j: i64| {
        let o = 4 * (j.rem_euclid(h) * w + i.rem_euclid(w)) as usize;
        Vec3::new(
            srgb_to_linear(t.rgba8[o]),
            srgb_to_linear(t.rgba8[o + 1]),
            srgb_to_linear(t.rgba8[o + 2]),
        )
    };
    let (i, j) = (x.floor() as i64, y.floor() as i64);
    let top = texel(i, j).lerp(texel(i + 1, j), fx);
    let bottom = texel(i, j + 1).lerp(texel(i + 1, j + 1), fx);
    top.lerp(bottom, fy)
}

/// Per square: the pixels checked and the largest difference of `albedo`
/// from the texture sampled at each pixel's own world position.
fn albedo_errors(
    positions: &[[f32; 4]],
    albedo: &[[f32; 4]],
    textures: &[Texture],
) -> Vec<(usize, f32)> {
    let mut out = vec![(0, 0f32); SIZES.len()];
    for (p, a) in positions.iter().zip(albedo) {
        let world = Vec3::from_slice(&p[..3]);
        let Some(i) = square_under(world) else {
            continue;
        };
        let expected = bilinear(&textures[i], uv_at(i, world));
        let got = Vec3::from_slice(&a[..3]);
        out[i].0 += 1;
        out[i].1 = out[i].1.max((got - expected).abs().max_element());
    }
    out
}

/// Each square's albedo in the G-buffer and in the path tracer is its
/// texture (white times the texture) sampled at the pixel's point, within
/// 0.01: the device's sRGB decoding and filtering, the 16-bit float albedo
/// target and the rounding of the point's texture coordinates (a wrong
/// texel is off by tenths). The arrays are at most eight; the texture
/// shrunk to 4096 wide fills its layer, and the others sit bordered in
/// larger ones (the sampler's taps across their edges read the border).
#[test]
fn each_texture_of_many_sizes_shows_where_it_is_mapped() {
    let scene = squares();
    let warnings = texture_arrays::warnings(&scene.textures);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("shrunk to 4096x3"), "{}", warnings[0]);
    let sampled: Vec<Texture> = texture_arrays::fitted(&scene.textures)
        .into_iter()
        .map(|t| t.into_owned())
        .collect();
    let gpu = validating_gpu();
    let (width, height) = (256, 256);
    let mut r = Renderer::new(&gpu, &scene, &sized("none", width, height, 64)).unwrap();
    let plan = r.scene.plan.clone();
    assert!(plan.arrays.len() <= ARRAYS);
    assert_eq!(r.scene.texture_arrays.len(), plan.arrays.len() + 1);
    let in_larger_layer = (0..SIZES.len())
        .filter(|&t| {
            let a = &plan.arrays[plan.placements[t].array as usize];
            plan.sizes[t] != (a.width, a.height)
        })
        .count();
    assert!(
        in_larger_layer > 0 && in_larger_layer < SIZES.len(),
        "{plan:?}"
    );
    r.render_frames(1, |_| {}).unwrap();
    let out = r.readback().unwrap();
    drop(r);
    assert_validation_clean(&gpu);
    let traced = common::traced::traced_once(&scene, width, height);
    for (who, r) in [("G-buffer", &out), ("path tracer", &traced)] {
        let errors = albedo_errors(&r.position, &r.albedo, &sampled);
        for (i, &(pixels, error)) in errors.iter().enumerate() {
            assert!(pixels > 300, "{who}: square {i} covers {pixels} pixels");
            assert!(
                error < 0.01,
                "{who}: texture {} ({}x{} sampled, layer {:?}) is off by {error}",
                scene.textures[i].name,
                plan.sizes[i].0,
                plan.sizes[i].1,
                plan.placements[i]
            );
        }
    }
}

/// A texture wider than a layer renders from the command line, shrunk to
/// fit with a warning that says so.
#[test]
fn a_texture_wider_than_a_layer_renders_shrunk_with_a_warning() {
    let dir = temp_dir("texture-arrays-wide");
    let texels: Vec<u8> = (0..4100 * 2)
        .flat_map(|i| [(i % 251) as u8, 90, 200])
        .collect();
    std::fs::write(dir.join("wide.png"), common::gltf::png(4100, 2, &texels)).unwrap();
    let mut d = common::gltf::Doc::cornell();
    common::gltf::with_texture(&mut d.json, serde_json::json!({"uri": "wide.png"}));
    let scene = common::gltf::write_scene(&dir, &d.embedded());
    let ran = common::cli::Isr::tiny(&dir)
        .args(["--method", "none", "--validate", "--scene"])
        .arg(&scene)
        .succeeds();
    assert!(
        ran.stderr.contains(
            "warning: texture layers are at most 4096x4096 on every device, so 1 texture(s) \
             are shrunk to fit (averaged in linear light): texture image 0 (unnamed) is \
             4100x2, shrunk to 4096x2"
        ),
        "{}",
        ran.stderr
    );
}
