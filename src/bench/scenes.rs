//! The scenes of `isr bench`. The stress scenes ([`SCENES`]), built by code
//! and written to `assets/NAME.gltf` by `cargo run --release --example
//! stress_scenes` (our own geometry, licensed with the repository): each is
//! as small as it can be while making its point, and each has an animation
//! (the light moves; in `hall` the camera moves too; in `moving-block` an
//! object moves). And the archive scenes ([`ARCHIVE`]): the OBJ scenes
//! researchers know, read from the archive folder (`ISR_SCENES`, or
//! `../shared/scenes` beside the repository; never copied into it), lit,
//! framed and moved by the scene descriptions `assets/archive/NAME.scene.json`
//! (compiled in, and loadable as they are with `--scene`).
//!
//! | name | point |
//! | --- | --- |
//! | `cornell` | the built-in default with its light sweep |
//! | `fine` | stairs, columns and a slatted screen: many depth and normal discontinuities, for eye-space refinement and invalid light patches |
//! | `hall` | 40 m hall of pillars, light far from most geometry: where HISR's distance-based refinement should pay; camera path |
//! | `slats` | light grazing a ribbed wall through thin blinds, moving across them: regular VPLs jump between surfaces |
//! | `moving-block` | a still light and a coloured block sliding through its spot |
//! | `sibenik` | the cathedral (73,564 triangles), a spot moving along the nave |
//! | `sponza` | the Dabrovic atrium (66,445), a low sun through the open roof, sweeping |
//! | `conference` | the conference room (331,179, 53,627 degenerate), a spot moving over the table |
//! | `bunny` | the Stanford bunny (69,451) on a floor in a room, the light circling it |

use crate::scene::animation::{
    rotation_looking_along, Animation, Channel, Interpolation, Local, Parent, Property, Trs,
};
use crate::scene::{cornell, cuboid, Camera, LightKind, Scene, SpotLight};
use glam::{Mat4, Vec3, Vec4};

/// A bench scene: its name, what it stresses, and the animation window the
/// bench samples (`start` seconds, then one frame every `1 / fps`).
#[derive(Clone, Copy, Debug)]
pub struct BenchScene {
    pub name: &'static str,
    pub about: &'static str,
    pub start: f32,
    pub fps: f32,
    /// An archive scene's description (`assets/archive/NAME.scene.json`);
    /// `None` for a scene built by code.
    pub description: Option<&'static str>,
    /// The image size (width = height) and RSM resolution the scene is
    /// benched at where the command line sets none; `None`: the run's.
    pub size: Option<(u32, u32)>,
    /// Its animation frames where the command line sets none.
    pub frames: Option<u32>,
}

/// The archive scenes at 64x64 with the stress scenes' RSM of 128 (so that
/// 4096 VPLs are a quarter of the texels, not all of them as at RSM 64),
/// and 3 frames: at the stress scenes' 128x128 and 6 frames a full sweep of
/// Sibenik alone took 103 s here (the five stress scenes take about 4
/// minutes).
const ARCHIVE_SIZE: Option<(u32, u32)> = Some((64, 128));
const ARCHIVE_FRAMES: Option<u32> = Some(3);

/// Every bench scene, in the order reports list them.
pub const SCENES: &[BenchScene] = &[
    BenchScene {
        name: "cornell",
        about: "Cornell box, light sweeping toward the green wall",
        start: 0.0,
        fps: 10.0,
        description: None,
        size: None,
        frames: None,
    },
    BenchScene {
        name: "fine",
        about: "stairs, columns and a slatted screen",
        start: 0.0,
        fps: 10.0,
        description: None,
        size: None,
        frames: None,
    },
    BenchScene {
        name: "hall",
        about: "40 m hall of pillars, light 14 m up, camera dollying",
        start: 0.0,
        fps: 10.0,
        description: None,
        size: None,
        frames: None,
    },
    BenchScene {
        name: "slats",
        about: "grazing light moving across a ribbed wall behind thin blinds",
        start: 0.0,
        fps: 10.0,
        description: None,
        size: None,
        frames: None,
    },
    BenchScene {
        name: "moving-block",
        about: "a red block sliding through a still spot",
        start: 0.0,
        fps: 10.0,
        description: None,
        size: None,
        frames: None,
    },
];

/// The archive scenes (`isr bench --scenes archive`), in report order.
pub const ARCHIVE: &[BenchScene] = &[
    BenchScene {
        name: "sibenik",
        about: "Sibenik cathedral, a spot moving along the nave",
        start: 0.0,
        fps: 10.0,
        description: Some(include_str!("../../assets/archive/sibenik.scene.json")),
        size: ARCHIVE_SIZE,
        frames: ARCHIVE_FRAMES,
    },
    BenchScene {
        name: "sponza",
        about: "Dabrovic Sponza, a low sun through the open roof, sweeping",
        start: 0.0,
        fps: 10.0,
        description: Some(include_str!("../../assets/archive/sponza.scene.json")),
        size: ARCHIVE_SIZE,
        frames: ARCHIVE_FRAMES,
    },
    BenchScene {
        name: "conference",
        about: "the conference room, a spot moving over the table",
        start: 0.0,
        fps: 10.0,
        description: Some(include_str!("../../assets/archive/conference.scene.json")),
        size: ARCHIVE_SIZE,
        frames: ARCHIVE_FRAMES,
    },
    BenchScene {
        name: "bunny",
        about: "the Stanford bunny on a floor in a room, the light circling it",
        start: 0.0,
        fps: 10.0,
        description: Some(include_str!("../../assets/archive/bunny.scene.json")),
        size: ARCHIVE_SIZE,
        frames: ARCHIVE_FRAMES,
    },
];

/// Names `--scenes` takes for several scenes: `stress` (the default),
/// `archive` and `all`.
pub fn group(name: &str) -> Option<Vec<&'static str>> {
    let names = |list: &[BenchScene]| list.iter().map(|s| s.name).collect::<Vec<_>>();
    match name {
        "stress" => Some(names(SCENES)),
        "archive" => Some(names(ARCHIVE)),
        "all" => Some(names(SCENES).into_iter().chain(names(ARCHIVE)).collect()),
        _ => None,
    }
}

/// The bench scene called `name`, or an error listing the valid names.
pub fn find(name: &str) -> anyhow::Result<&'static BenchScene> {
    SCENES
        .iter()
        .chain(ARCHIVE)
        .find(|s| s.name == name)
        .ok_or_else(|| {
            let names: Vec<&str> = SCENES.iter().chain(ARCHIVE).map(|s| s.name).collect();
            anyhow::anyhow!(
                "unknown scene '{name}'; the bench scenes are: {} (and the groups stress, archive, all)",
                names.join(", ")
            )
        })
}

/// An archive scene, from its description (its mesh from the archive
/// folder); the error says how to get the archive when it is missing.
fn archive(s: &BenchScene, description: &str) -> anyhow::Result<Scene> {
    let path = std::path::PathBuf::from(format!("assets/archive/{}.scene.json", s.name));
    crate::scene::description::load_bytes(&path, description.as_bytes(), &Default::default())
        .map_err(|e| e.context(format!("bench scene {}", s.name)))
}

/// Builds the scene by name (`cornell` is the built-in box; the archive
/// scenes are loaded).
pub fn build(name: &str) -> anyhow::Result<Scene> {
    let s = find(name)?;
    if let Some(d) = s.description {
        return archive(s, d);
    }
    Ok(match s.name {
        "cornell" => cornell::cornell_box(),
        "fine" => fine(),
        "hall" => hall(),
        "slats" => slats(),
        "moving-block" => moving_block(),
        other => unreachable!("scene {other} is listed but not built"),
    })
}

/// The keyframes of a light (or camera) moving along `keys` of (time,
/// position, point aimed at), linearly: a translation and a rotation channel
/// on one node. Returns the node.
fn path(a: &mut Animation, keys: &[(f32, Vec3, Vec3)]) -> usize {
    let ok = "the scene's built-in path is valid";
    let rest = Trs {
        translation: keys[0].1,
        rotation: rotation_looking_along(keys[0].2 - keys[0].1),
        scale: Vec3::ONE,
    };
    let node = a
        .add_node(Parent::Fixed(Mat4::IDENTITY), Local::Animated(rest))
        .expect(ok);
    let times: Vec<f32> = keys.iter().map(|k| k.0).collect();
    let translations = keys.iter().map(|k| k.1.extend(0.0)).collect();
    let rotations = keys
        .iter()
        .map(|k| Vec4::from(rotation_looking_along(k.2 - k.1)))
        .collect();
    for (property, values) in [
        (Property::Translation, translations),
        (Property::Rotation, rotations),
    ] {
        let c =
            Channel::new(node, property, Interpolation::Linear, times.clone(), values).expect(ok);
        a.add_channel(c).expect(ok);
    }
    node
}

fn spot(position: Vec3, target: Vec3, intensity: f32, outer_deg: f32) -> SpotLight {
    SpotLight {
        kind: LightKind::Spot,
        position,
        direction: (target - position).normalize(),
        color: Vec3::ONE,
        intensity,
        inner_cone: (outer_deg * 0.75).to_radians(),
        outer_cone: outer_deg.to_radians(),
        range: None,
    }
}

fn add_box(s: &mut Scene, name: &str, center: Vec3, size: Vec3, material: usize) {
    let (v, i) = cuboid(center, size, 0.0);
    s.add_mesh(name, v, i, material);
}

/// Floor and walls of an open-fronted room `w` x `d` x `h`, centred on x = 0,
/// back wall at z = -d/2 (faces into the room, single-sided).
fn room(s: &mut Scene, w: f32, d: f32, h: f32, walls: [usize; 4]) {
    let (x, z) = (w * 0.5, d * 0.5);
    let v = Vec3::new;
    let [floor, back, left, right] = walls;
    s.add_quad(
        "floor",
        [v(-x, 0., z), v(x, 0., z), v(x, 0., -z), v(-x, 0., -z)],
        floor,
    );
    s.add_quad(
        "back",
        [v(-x, 0., -z), v(x, 0., -z), v(x, h, -z), v(-x, h, -z)],
        back,
    );
    s.add_quad(
        "left",
        [v(-x, 0., z), v(-x, 0., -z), v(-x, h, -z), v(-x, h, z)],
        left,
    );
    s.add_quad(
        "right",
        [v(x, 0., -z), v(x, 0., z), v(x, h, z), v(x, h, -z)],
        right,
    );
}

/// Stairs up the left, a row of thin columns, a slatted screen on the right;
/// the spot sweeps from the stairs across the columns to the screen.
pub fn fine() -> Scene {
    let light = spot(
        Vec3::new(-1.0, 2.8, 1.0),
        Vec3::new(-0.8, 0.0, -0.6),
        14.0,
        50.0,
    );
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.6, 4.2),
        Vec3::new(0.0, 0.7, 0.0),
        Vec3::Y,
        45f32.to_radians(),
        0.05,
    );
    let mut s = Scene::empty("fine", light, camera);
    let white = s.add_material("white", Vec3::splat(0.75));
    let blue = s.add_material("blue", Vec3::new(0.1, 0.2, 0.6));
    let orange = s.add_material("orange", Vec3::new(0.8, 0.4, 0.1));
    room(&mut s, 4.0, 3.0, 3.0, [white, white, blue, orange]);
    // Eight steps, 0.15 m rise, 0.25 m going, climbing toward the back.
    for k in 0..8 {
        let h = 0.15 * (k + 1) as f32;
        let z = 1.0 - 0.25 * k as f32;
        add_box(
            &mut s,
            &format!("step-{k}"),
            Vec3::new(-1.3, h * 0.5, z),
            Vec3::new(1.2, h, 0.25),
            white,
        );
    }
    // Five 0.1 m columns.
    for k in 0..5 {
        add_box(
            &mut s,
            &format!("column-{k}"),
            Vec3::new(-0.3 + 0.3 * k as f32, 0.9, -0.6),
            Vec3::new(0.1, 1.8, 0.1),
            white,
        );
    }
    // A slatted screen: twelve 3 cm slats, 8 cm apart, in front of the right wall.
    for k in 0..12 {
        add_box(
            &mut s,
            &format!("slat-{k}"),
            Vec3::new(1.0 + 0.08 * k as f32 - 0.44, 1.0, 0.6),
            Vec3::new(0.03, 2.0, 0.02),
            orange,
        );
    }
    let mut a = Animation::default();
    let node = path(
        &mut a,
        &[
            (0.0, light.position, Vec3::new(-0.8, 0.0, -0.6)),
            (2.0, Vec3::new(0.0, 2.8, 1.2), Vec3::new(0.2, 0.5, -0.6)),
            (4.0, Vec3::new(1.0, 2.8, 1.6), Vec3::new(1.0, 0.5, 0.4)),
        ],
    );
    a.attach_light(0, node);
    s.animation = Some(a);
    s
}

/// A 40 x 40 m hall: 5 x 5 pillars 8 m tall on a 7 m grid, walls on two sides,
/// the spot 14 m up over one corner; the light drifts along the back wall
/// while the camera dollies in.
pub fn hall() -> Scene {
    let target = Vec3::new(0.0, 0.0, -4.0);
    let light = spot(Vec3::new(-14.0, 14.0, 8.0), target, 900.0, 45.0);
    let eye = Vec3::new(0.0, 5.0, 24.0);
    let camera = Camera::look_at(
        eye,
        Vec3::new(0.0, 2.0, -6.0),
        Vec3::Y,
        50f32.to_radians(),
        0.1,
    );
    let mut s = Scene::empty("hall", light, camera);
    let stone = s.add_material("stone", Vec3::new(0.7, 0.68, 0.62));
    let red = s.add_material("red", Vec3::new(0.6, 0.12, 0.08));
    let green = s.add_material("green", Vec3::new(0.15, 0.45, 0.12));
    room(&mut s, 40.0, 40.0, 10.0, [stone, red, green, stone]);
    for i in 0..5 {
        for j in 0..5 {
            add_box(
                &mut s,
                &format!("pillar-{i}-{j}"),
                Vec3::new(-14.0 + 7.0 * i as f32, 4.0, -14.0 + 7.0 * j as f32),
                Vec3::new(0.8, 8.0, 0.8),
                stone,
            );
        }
    }
    let mut a = Animation::default();
    let l = path(
        &mut a,
        &[
            (0.0, light.position, target),
            (4.0, Vec3::new(10.0, 14.0, 8.0), Vec3::new(4.0, 0.0, -6.0)),
        ],
    );
    a.attach_light(0, l);
    let c = path(
        &mut a,
        &[
            (0.0, eye, Vec3::new(0.0, 2.0, -6.0)),
            (4.0, Vec3::new(-4.0, 4.0, 14.0), Vec3::new(0.0, 2.0, -8.0)),
        ],
    );
    a.attach_camera(c);
    s.animation = Some(a);
    s
}

/// A wall of 24 vertical ribs (4 cm wide, 6 cm deep, 12 cm apart) lit at a
/// grazing angle through eight thin horizontal blinds; the light slides
/// along the wall.
pub fn slats() -> Scene {
    let light = spot(
        Vec3::new(-1.6, 1.2, 0.9),
        Vec3::new(0.0, 1.0, -1.0),
        10.0,
        40.0,
    );
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.2, 3.0),
        Vec3::new(0.0, 0.9, -1.0),
        Vec3::Y,
        45f32.to_radians(),
        0.05,
    );
    let mut s = Scene::empty("slats", light, camera);
    let white = s.add_material("white", Vec3::splat(0.75));
    let yellow = s.add_material("yellow", Vec3::new(0.75, 0.6, 0.1));
    let teal = s.add_material("teal", Vec3::new(0.1, 0.5, 0.5));
    room(&mut s, 3.2, 2.4, 2.4, [white, white, white, teal]);
    for k in 0..24 {
        add_box(
            &mut s,
            &format!("rib-{k}"),
            Vec3::new(-1.38 + 0.12 * k as f32, 1.2, -1.17),
            Vec3::new(0.04, 2.4, 0.06),
            yellow,
        );
    }
    // Blinds: 1 cm thick, 6 cm deep, 10 cm apart, 0.6 m in front of the wall.
    for k in 0..8 {
        add_box(
            &mut s,
            &format!("blind-{k}"),
            Vec3::new(0.0, 0.9 + 0.1 * k as f32, -0.5),
            Vec3::new(1.6, 0.01, 0.06),
            white,
        );
    }
    let mut a = Animation::default();
    let node = path(
        &mut a,
        &[
            (0.0, light.position, Vec3::new(0.0, 1.0, -1.0)),
            (4.0, Vec3::new(1.6, 1.2, 0.9), Vec3::new(0.0, 1.0, -1.0)),
        ],
    );
    a.attach_light(0, node);
    s.animation = Some(a);
    s
}

/// A small white room, a still spot, and a red block sliding across the lit floor.
pub fn moving_block() -> Scene {
    let light = spot(
        Vec3::new(0.0, 2.3, 0.6),
        Vec3::new(0.0, 0.0, -0.3),
        10.0,
        55.0,
    );
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.3, 3.4),
        Vec3::new(0.0, 0.6, 0.0),
        Vec3::Y,
        45f32.to_radians(),
        0.05,
    );
    let mut s = Scene::empty("moving-block", light, camera);
    let white = s.add_material("white", Vec3::splat(0.75));
    let red = s.add_material("red", Vec3::new(0.7, 0.08, 0.05));
    room(&mut s, 3.0, 2.4, 2.4, [white, white, white, white]);
    add_box(&mut s, "block", Vec3::ZERO, Vec3::new(0.4, 0.6, 0.4), red);
    let block = s.instances.len() - 1;
    let mut a = Animation::default();
    let rest = Trs {
        translation: Vec3::new(-1.0, 0.3, -0.3),
        rotation: glam::Quat::IDENTITY,
        scale: Vec3::ONE,
    };
    let ok = "the block's path is valid";
    let node = a
        .add_node(Parent::Fixed(Mat4::IDENTITY), Local::Animated(rest))
        .expect(ok);
    let c = Channel::new(
        node,
        Property::Translation,
        Interpolation::Linear,
        vec![0.0, 4.0],
        vec![
            Vec4::new(-1.0, 0.3, -0.3, 0.0),
            Vec4::new(1.0, 0.3, -0.3, 0.0),
        ],
    )
    .expect(ok);
    a.add_channel(c).expect(ok);
    a.attach_instance(block, node);
    s.animation = Some(a);
    s
}
