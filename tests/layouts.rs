//! Host structs (`src/gpu_types.rs`) against the layouts glslang gave the
//! structs of `shaders/shared.glsl`, read from the compiled SPIR-V.

use isr::gpu_types::{
    DrawPush, FrameUniforms, GridLevelPush, InstanceTransform, LightPatch, MaterialGpu,
    RunUniforms, VoxelizePush,
};
use isr::methods::hisr::gpu::HisrCutHeader;
use std::collections::HashMap;
use std::mem::{offset_of, size_of};

const OP_NAME: u32 = 5;
const OP_MEMBER_NAME: u32 = 6;
const OP_MEMBER_DECORATE: u32 = 72;
const DECORATION_OFFSET: u32 = 35;

use isr::vk::reflect::string_at;

/// For every struct type named `name` in `shader`: member name -> byte offset.
fn struct_layouts(shader: &str, name: &str) -> Vec<HashMap<String, u32>> {
    let words = isr::vk::pipeline::spirv(shader).unwrap();
    assert_eq!(words[0], 0x0723_0203, "not SPIR-V");
    let mut names: HashMap<u32, String> = HashMap::new();
    let mut member_names: HashMap<(u32, u32), String> = HashMap::new();
    let mut offsets: HashMap<(u32, u32), u32> = HashMap::new();
    let mut i = 5;
    while i < words.len() {
        let (op, count) = (words[i] & 0xffff, (words[i] >> 16) as usize);
        let ins = &words[i..i + count];
        match op {
            OP_NAME => {
                names.insert(ins[1], string_at(&ins[2..]));
            }
            OP_MEMBER_NAME => {
                member_names.insert((ins[1], ins[2]), string_at(&ins[3..]));
            }
            OP_MEMBER_DECORATE if ins[3] == DECORATION_OFFSET => {
                offsets.insert((ins[1], ins[2]), ins[4]);
            }
            _ => {}
        }
        i += count;
    }
    let ids: Vec<u32> = names
        .iter()
        .filter(|(_, n)| *n == name)
        .map(|(id, _)| *id)
        .collect();
    let layouts: Vec<HashMap<String, u32>> = ids
        .iter()
        .map(|id| {
            offsets
                .iter()
                .filter(|((sid, _), _)| sid == id)
                .map(|((sid, m), off)| (member_names[&(*sid, *m)].clone(), *off))
                .collect::<HashMap<_, _>>()
        })
        .filter(|m| !m.is_empty())
        .collect();
    assert!(
        !layouts.is_empty(),
        "{shader} has no laid-out struct {name}"
    );
    layouts
}

macro_rules! check {
    ($shader:expr, $ty:ident, $glsl:expr, $last:ident : $last_size:expr, [$($field:ident => $member:expr),* $(,)?]) => {
        for layout in struct_layouts($shader, $glsl) {
            $(
                assert_eq!(
                    layout.get($member).copied(),
                    Some(offset_of!($ty, $field) as u32),
                    "{}::{} vs GLSL {}.{} in {}", stringify!($ty), stringify!($field), $glsl, $member, $shader
                );
            )*
            // Every GLSL member is one of the host's, and none is missing: a
            // member appended on either side fails here.
            let mut glsl: Vec<&str> = layout.keys().map(String::as_str).collect();
            let mut host: Vec<&str> = vec![$($member),*];
            glsl.sort();
            host.sort();
            assert_eq!(glsl, host, "members of {} in {}", $glsl, $shader);
            let glsl_size = layout[stringify!($last)] as usize + $last_size;
            assert_eq!(size_of::<$ty>(), glsl_size, "size of {}", stringify!($ty));
        }
    };
}

#[test]
fn frame_uniforms_match_shared_glsl() {
    for shader in [
        "rsm.frag",
        "direct_light.frag",
        "scene.vert",
        "tonemap.frag",
    ] {
        check!(shader, FrameUniforms, "FrameUniforms", shadow_view_proj: 64, [
            camera_view_proj => "camera_view_proj",
            light_view_proj => "light_view_proj",
            camera_position => "camera_position",
            pad0 => "pad0",
            camera_forward => "camera_forward",
            normal_depth_scale => "normal_depth_scale",
            light_position => "light_position",
            light_range => "light_range",
            light_direction => "light_direction",
            light_kind => "light_kind",
            light_intensity => "light_intensity",
            light_peak => "light_peak",
            cone_scale => "cone_scale",
            cone_offset => "cone_offset",
            rsm_half_extent => "rsm_half_extent",
            rsm_depth_range => "rsm_depth_range",
            cube_face => "cube_face",
            light_index => "light_index",
            shadow_half_extent => "shadow_half_extent",
            pad3 => "pad3",
            cube_view_proj => "cube_view_proj",
            grid_cube => "grid_cube",
            scene_min => "scene_min",
            pad4 => "pad4",
            scene_max => "scene_max",
            pad5 => "pad5",
            shadow_view_proj => "shadow_view_proj",
        ]);
    }
}

#[test]
fn run_uniforms_match_shared_glsl() {
    for shader in [
        "direct_light.frag",
        "hisr/gather.frag",
        "multires/upsample.comp",
    ] {
        check!(shader, RunUniforms, "RunUniforms", pad2: 4, [
            shadow_normal_offset => "shadow_normal_offset",
            shadow_depth_bias => "shadow_depth_bias",
            pcf_radius => "pcf_radius",
            shadow_slope_bias => "shadow_slope_bias",
            output_size => "output_size",
            rsm_resolution => "rsm_resolution",
            rsm_top_level => "rsm_top_level",
            exposure => "exposure",
            levels => "levels",
            depth_threshold => "depth_threshold",
            normal_chord => "normal_chord",
            hierarchy_flags => "hierarchy_flags",
            validity_depth => "validity_depth",
            validity_normal_cos => "validity_normal_cos",
            patch_kernel => "patch_kernel",
            grid_side => "grid_side",
            grid_levels => "grid_levels",
            shadow_resolution => "shadow_resolution",
            pad1 => "pad1",
            pad2 => "pad2",
        ]);
    }
}

#[test]
fn instance_transform_matches_shared_glsl() {
    check!("scene.vert", InstanceTransform, "InstanceTransform", normal_from_object: 64, [
        world_from_object => "world_from_object",
        normal_from_object => "normal_from_object",
    ]);
}

#[test]
fn light_patch_matches_shared_glsl() {
    check!("isr/select.comp", LightPatch, "LightPatch", flux: 16, [
        position_area => "position_area",
        normal => "normal",
        flux => "flux",
    ]);
}

#[test]
fn hisr_cut_header_matches_shared_glsl() {
    for shader in ["hisr/cut.comp", "hisr/gather.frag", "hisr/visibility.comp"] {
        check!(shader, HisrCutHeader, "HisrCutHeader", points: 16, [
            tiles => "tiles",
            entries => "entries",
            capacity => "capacity",
            visibility => "visibility",
            points => "points",
        ]);
    }
}

#[test]
fn material_matches_shared_glsl() {
    check!("gbuffer.frag", MaterialGpu, "MaterialGpu", pad0: 8, [
        base_color => "base_color",
        texture_array => "texture_array",
        texture_layer => "texture_layer",
        texture_scale => "texture_scale",
        texture_offset => "texture_offset",
        pad0 => "pad0",
    ]);
}

#[test]
fn draw_push_matches_shared_glsl() {
    check!("scene.vert", DrawPush, "DrawPush", material: 4, [
        instance => "instance",
        material => "material",
    ]);
}

#[test]
fn voxelize_push_matches_shared_glsl() {
    check!("voxel_grid/voxelize.comp", VoxelizePush, "VoxelizePush", triangles: 4, [
        first_index => "first_index",
        vertex_offset => "vertex_offset",
        instance => "instance",
        first_triangle => "first_triangle",
        triangles => "triangles",
    ]);
}

#[test]
fn grid_level_push_matches_shared_glsl() {
    check!("voxel_grid/levels.comp", GridLevelPush, "GridLevelPush", level: 4, [
        level => "level",
    ]);
}

#[test]
fn viewer_pushes_match_shared_glsl() {
    use isr::gpu_types::{OverlayPush, PresentPush};
    check!("viewer/present.frag", PresentPush, "PresentPush", pad1: 4, [
        rect => "rect",
        letterbox => "letterbox",
        view => "view",
        srgb_target => "srgb_target",
        pad0 => "pad0",
        pad1 => "pad1",
    ]);
    for shader in ["viewer/overlay_text.vert", "viewer/overlay_text.frag"] {
        check!(shader, OverlayPush, "OverlayPush", target: 16, [
            rect => "rect",
            target => "target",
        ]);
    }
}

/// The value of `const ... NAME = VALUE;` in `shaders/FILE`.
fn glsl_constant(file: &str, name: &str) -> String {
    let path = format!("{}/shaders/{file}", env!("CARGO_MANIFEST_DIR"));
    let glsl = std::fs::read_to_string(&path).unwrap();
    let line = glsl
        .lines()
        .find(|l| l.starts_with("const ") && l.contains(&format!(" {name} = ")))
        .unwrap_or_else(|| panic!("{name} not in {path}"));
    line.split('=')
        .nth(1)
        .unwrap()
        .split(';')
        .next()
        .unwrap()
        .trim()
        .trim_end_matches('u')
        .to_string()
}

/// The flag constants are written twice (GLSL and Rust); read GLSL's.
#[test]
fn flag_constants_match_shared_glsl() {
    let value = |name: &str| -> u32 { glsl_constant("shared.glsl", name).parse().unwrap() };
    use isr::gpu_types::*;
    assert_eq!(value("HIERARCHY_STENCIL_OFF"), HIERARCHY_STENCIL_OFF as u32);
    assert_eq!(value("GEO_HAS_GEOMETRY"), GEO_HAS_GEOMETRY);
    assert_eq!(value("GEO_SMOOTH"), GEO_SMOOTH);
    assert_eq!(value("GEO_SPLIT"), GEO_SPLIT);
    assert_eq!(value("PRESENT_VIEW_FINAL"), PRESENT_VIEW_FINAL as u32);
    assert_eq!(value("PRESENT_VIEW_INDIRECT"), PRESENT_VIEW_INDIRECT as u32);
    assert_eq!(value("PRESENT_VIEW_HOST"), PRESENT_VIEW_HOST as u32);
    assert_eq!(value("LIGHT_SPOT"), LIGHT_SPOT as u32);
    assert_eq!(value("LIGHT_POINT"), LIGHT_POINT as u32);
    assert_eq!(value("LIGHT_DIRECTIONAL"), LIGHT_DIRECTIONAL as u32);
    assert_eq!(value("PATCH_KERNEL_CENTRE"), PATCH_KERNEL_CENTRE as u32);
    assert_eq!(
        value("PATCH_KERNEL_SECOND_ORDER"),
        PATCH_KERNEL_SECOND_ORDER as u32
    );
    let float = |name: &str| -> f32 { glsl_constant("shared.glsl", name).parse().unwrap() };
    assert_eq!(float("PATCH_EMPTY"), PATCH_EMPTY);
    assert_eq!(float("PATCH_VALID"), PATCH_VALID);
    assert_eq!(float("PATCH_INVALID"), PATCH_INVALID);
}

/// The bounce passes' cells (`isr::bounce`) against
/// `shaders/bounce/bounce.glsl`: the cells per side, the faces per cell and
/// the vec4s per cell the host sizes the buffers by.
#[test]
fn bounce_constants_match_bounce_glsl() {
    let text = |name: &str| glsl_constant("bounce/bounce.glsl", name);
    assert_eq!(
        text("BOUNCE_SIDE").parse::<u32>().unwrap(),
        isr::bounce::SIDE
    );
    assert_eq!(
        text("BOUNCE_FACES").parse::<u32>().unwrap(),
        isr::bounce::FACES
    );
    assert_eq!(text("BOUNCE_CELL_VEC4S"), "1 + 3 * BOUNCE_FACES");
    assert_eq!(isr::bounce::CELL_VEC4S, 1 + 3 * isr::bounce::FACES);
}

/// HISR's constants (`methods::hisr::gpu`) against `shaders/hisr/hisr.glsl`.
#[test]
fn hisr_constants_match_hisr_glsl() {
    use isr::methods::hisr::gpu::*;
    let text = |name: &str| glsl_constant("hisr/hisr.glsl", name);
    assert_eq!(
        text("HISR_CUT_OVERFLOW").parse::<u32>().unwrap(),
        HISR_CUT_OVERFLOW
    );
    assert_eq!(
        text("HISR_CUT_LEVELS").parse::<usize>().unwrap(),
        HISR_CUT_LEVELS
    );
    assert_eq!(
        text("HISR_INVALID_TAU_SCALE").parse::<f32>().unwrap(),
        HISR_INVALID_TAU_SCALE
    );
}

#[test]
fn every_shader_in_the_directory_is_embedded() {
    fn walk(dir: &std::path::Path, root: &std::path::Path, out: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, root, out);
            } else {
                let name = path.strip_prefix(root).unwrap().to_str().unwrap();
                out.push(name.replace('\\', "/"));
            }
        }
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut files = vec![];
    walk(&root, &root, &mut files);
    let embedded: Vec<&str> = isr::vk::pipeline::shader_names().collect();
    // In folders too (`hisr/cut.comp`).
    assert!(files.iter().any(|f| f.contains('/')), "{files:?}");
    for name in files.iter().filter(|n| !n.ends_with(".glsl")) {
        assert!(
            embedded.contains(&name.as_str()),
            "{name} was not compiled into the binary"
        );
    }
}

/// The descriptor bindings a pass declares on the host are checked against
/// the shader's SPIR-V when its pipeline is made: a swapped pair of bindings
/// of the same type, a missing or extra binding, or the wrong kind fails.
mod bindings {
    use isr::vk::pipeline::{check_bindings, BindingInfo};
    use isr::vk::reflect::Kind;

    fn sampled(name: &'static str) -> BindingInfo {
        BindingInfo {
            name,
            kind: Kind::CombinedImageSampler,
        }
    }

    fn frame() -> Vec<BindingInfo> {
        let ubo = |name| BindingInfo {
            name,
            kind: Kind::UniformBuffer,
        };
        vec![
            ubo("Frame"),
            ubo("Run"),
            BindingInfo {
                name: "Transforms",
                kind: Kind::StorageBuffer,
            },
            // Read by the patch formula (voxel_grid/march.glsl), written by
            // voxel_grid/voxelize.comp.
            BindingInfo {
                name: "GridOccupancy",
                kind: Kind::StorageBuffer,
            },
        ]
    }

    const SHADERS: [&str; 2] = ["fullscreen.vert", "composite.frag"];

    #[test]
    fn the_composite_bindings_as_the_pass_makes_them_pass() {
        let own = [
            sampled("direct_radiance"),
            sampled("gbuffer_albedo"),
            sampled("indirect_irradiance"),
        ];
        check_bindings("composite", &SHADERS, &[&frame(), &own]).unwrap();
    }

    #[test]
    fn swapped_bindings_of_one_type_are_rejected() {
        let own = [
            sampled("gbuffer_albedo"),
            sampled("direct_radiance"),
            sampled("indirect_irradiance"),
        ];
        let e = check_bindings("composite", &SHADERS, &[&frame(), &own]).unwrap_err();
        assert!(e.to_string().contains("expects `direct_radiance`"), "{e}");
    }

    #[test]
    fn missing_extra_and_mistyped_bindings_are_rejected() {
        let two = [sampled("direct_radiance"), sampled("gbuffer_albedo")];
        let e = check_bindings("composite", &SHADERS, &[&frame(), &two]).unwrap_err();
        assert!(e.to_string().contains("does not bind"), "{e}");
        let four = [
            sampled("direct_radiance"),
            sampled("gbuffer_albedo"),
            sampled("indirect_irradiance"),
            sampled("unused"),
        ];
        let e = check_bindings("composite", &SHADERS, &[&frame(), &four]).unwrap_err();
        assert!(e.to_string().contains("none of"), "{e}");
        let mut typed = vec![
            sampled("direct_radiance"),
            sampled("gbuffer_albedo"),
            sampled("indirect_irradiance"),
        ];
        typed[2].kind = Kind::StorageImage;
        let e = check_bindings("composite", &SHADERS, &[&frame(), &typed]).unwrap_err();
        assert!(e.to_string().contains("StorageImage"), "{e}");
        let e = check_bindings("composite", &SHADERS, &[&frame()]).unwrap_err();
        assert!(e.to_string().contains("binds 1 set(s)"), "{e}");
    }

    #[test]
    fn every_compiled_shader_reflects_its_bindings() {
        // Each shader's set 0 is the frame set, named as `shaders/frame.glsl` names it.
        let frame = frame();
        for name in isr::vk::pipeline::shader_names() {
            let words = isr::vk::pipeline::spirv(name).unwrap();
            let bindings = isr::vk::reflect::bindings(&words).unwrap();
            for b in bindings.iter().filter(|b| b.set == 0) {
                let host = &frame[b.binding as usize];
                assert_eq!((host.name, host.kind), (b.name.as_str(), b.kind), "{name}");
            }
            // Set 1 is a pass's own, or the scene's for a pass that draws
            // the scene with its textures and brings its own set as set 2
            // (the voxel surface pass); `check_bindings` checks those sets
            // by name where each pipeline is made.
            assert!(
                bindings.iter().all(|b| b.set <= 2 && b.kind != Kind::Other),
                "{name}: {bindings:?}"
            );
        }
    }
}

/// Specialization constants are set by name (`vk::specialization`): every
/// one a shader declares has a name, and a name means one id and one type in
/// every shader that declares it, so an id never means two things.
#[test]
fn every_specialization_constant_has_one_name_id_and_type() {
    use std::collections::HashMap;
    let mut seen: HashMap<String, (u32, isr::vk::reflect::SpecKind, &str)> = HashMap::new();
    let mut ids: HashMap<u32, String> = HashMap::new();
    for shader in isr::vk::pipeline::shader_names() {
        let words = isr::vk::pipeline::spirv(shader).unwrap();
        for c in isr::vk::reflect::spec_constants(&words).unwrap() {
            println!("{shader}: {} = {} ({:?})", c.name, c.id, c.kind);
            assert!(
                !c.name.is_empty(),
                "{shader}: constant {} has no name",
                c.id
            );
            match seen.get(&c.name) {
                Some(&(id, kind, first)) => assert_eq!(
                    (id, kind),
                    (c.id, c.kind),
                    "{} is id {id} ({kind:?}) in {first} but id {} ({:?}) in {shader}",
                    c.name,
                    c.id,
                    c.kind
                ),
                None => {
                    seen.insert(c.name.clone(), (c.id, c.kind, shader));
                }
            }
            let name = ids.entry(c.id).or_insert_with(|| c.name.clone());
            assert_eq!(
                *name, c.name,
                "id {} names both {name} and {} ({shader})",
                c.id, c.name
            );
        }
    }
}

/// A pipeline sets its shaders' specialization constants by name, checked
/// against their SPIR-V when it is made: a missing, unknown, repeated or
/// mistyped constant fails.
mod specialization {
    use isr::vk::pipeline::{check_specialization, Spec};

    const SHADERS: [&str; 2] = ["multires/layered.vert", "multires/stencil_refine.frag"];

    #[test]
    fn the_constants_the_shaders_declare_pass() {
        check_specialization("stencil-refine", &SHADERS, &[Spec::bool("COUNT", true)]).unwrap();
    }

    #[test]
    fn missing_unknown_repeated_and_mistyped_constants_are_rejected() {
        let e = check_specialization("stencil-refine", &SHADERS, &[]).unwrap_err();
        assert!(e.to_string().contains("does not set"), "{e}");
        let e = check_specialization(
            "stencil-refine",
            &SHADERS,
            &[Spec::bool("COUNT", true), Spec::bool("CONUT", true)],
        )
        .unwrap_err();
        assert!(e.to_string().contains("none of its shaders"), "{e}");
        let e = check_specialization(
            "stencil-refine",
            &SHADERS,
            &[Spec::bool("COUNT", true), Spec::bool("COUNT", false)],
        )
        .unwrap_err();
        assert!(e.to_string().contains("twice"), "{e}");
        let e =
            check_specialization("stencil-refine", &SHADERS, &[Spec::int("COUNT", 1)]).unwrap_err();
        assert!(e.to_string().contains("as Bool"), "{e}");
    }
}
