//! Option values the renderer cannot take, run through the release binary:
//! sizes that are empty, huge or not powers of two, levels and VPL counts out
//! of range, combinations a method refuses, negative values (which must
//! reach the range check, not be read as flags), a sample count that would
//! hang the path tracer, a one-pixel image, and no Vulkan driver. Each is a
//! clear message and a non-zero exit, never a panic.
mod common;

use common::cli::Isr;
use common::temp_dir;

/// `isr render` with `args` in a fresh folder; expects a clean failure and
/// returns its message.
fn fails(name: &str, args: &[&str]) -> String {
    let dir = temp_dir(name);
    Isr::render(&dir).args(["--frames", "1"]).args(args).fails()
}

#[test]
fn sizes_out_of_range_are_named() {
    let e = fails(
        "opt-zero",
        &["--width", "0", "--height", "32", "--rsm", "32"],
    );
    assert!(e.contains("resolution 0x32 is empty"), "{e}");
    let e = fails(
        "opt-huge",
        &["--width", "1000000", "--height", "32", "--rsm", "32"],
    );
    assert!(
        e.contains("exceeds what") && e.contains("--width/--height"),
        "{e}"
    );
    let e = fails(
        "opt-rsm",
        &["--width", "32", "--height", "32", "--rsm", "100"],
    );
    assert!(e.contains("power of two"), "{e}");
}

#[test]
fn method_parameters_out_of_range_are_named() {
    let small = ["--width", "32", "--height", "32", "--rsm", "32"];
    let cases: [(&str, &[&str], &str); 4] = [
        ("opt-levels", &["--levels", "40"], "--levels 40"),
        ("opt-vpls", &["--vpls", "200"], "power of 4"),
        (
            "opt-splat-stencil",
            &["--method", "multires-splat", "--stencil", "off"],
            "--stencil off",
        ),
        (
            "opt-tile-level",
            &["--method", "hisr", "--hisr-tile-level", "9"],
            "--hisr-tile-level 9",
        ),
    ];
    for (name, args, expect) in cases {
        let e = fails(name, &[&small[..], args].concat());
        assert!(e.contains(expect), "{args:?}: {e}");
    }
}

#[test]
fn negative_option_values_reach_the_range_check() {
    let dir = temp_dir("opt-negative");
    let e = Isr::tiny(&dir).args(["--tau", "-1"]).fails();
    assert!(
        e.contains("--tau -1") && !e.contains("unexpected argument"),
        "{e}"
    );
}

/// 2^32 - 1 samples per pixel would trace for days: the value is refused
/// while the arguments are read, before anything is traced or written.
#[test]
fn spp_is_bounded() {
    let dir = temp_dir("opt-spp");
    let e = Isr::tiny(&dir)
        .args(["--method", "pathtrace", "--spp", "4294967295"])
        .args(["--out", "o.exr", "--png", "o.png"])
        .fails();
    assert!(e.contains("--spp") && e.contains("1..=65536"), "{e}");
    assert!(
        !dir.join("o.exr").exists() && !dir.join("o.png").exists(),
        "something was rendered"
    );
}

#[test]
fn a_one_pixel_image_names_the_resolution_not_levels() {
    let dir = temp_dir("opt-one-pixel");
    let one_pixel = |method: &str| {
        Isr::render(&dir)
            .args([
                "--width", "1", "--height", "1", "--rsm", "32", "--vpls", "16",
            ])
            .args(["--frames", "1", "--method", method])
    };
    let e = one_pixel("hisr").fails();
    // Not an error about a --levels value (the message may point to which
    // methods read --levels).
    let names_a_levels_value = e
        .match_indices("--levels ")
        .any(|(i, m)| e[i + m.len()..].starts_with(|c: char| c.is_ascii_digit()));
    assert!(
        e.contains("resolution 1x1") && e.contains("at least 2x2") && !names_a_levels_value,
        "{e}"
    );
    // Methods without the multiresolution buffer render one pixel.
    one_pixel("rsm-gather").succeeds();
}

#[test]
fn no_vulkan_device_says_how_to_install_a_driver() {
    let dir = temp_dir("opt-nodevice");
    let ran = Isr::tiny(&dir)
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .run();
    let e = ran.clean_failure();
    assert!(
        e.contains("mesa-vulkan-drivers"),
        "the message should say how to install a driver:\n{e}"
    );
}

/// Issue 29, item 11: a size refused for memory says the rule (the share of
/// the heap a run may take), and its numbers agree with the refusal.
#[test]
fn a_memory_refusal_states_the_share_of_the_heap_it_allows() {
    let e = fails(
        "opt-memory",
        &["--width", "16384", "--height", "16384", "--rsm", "64"],
    );
    let mib_after = |what: &str| -> u64 {
        let rest = &e[e
            .find(what)
            .unwrap_or_else(|| panic!("no '{what}' in:\n{e}"))
            + what.len()..];
        let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
        digits
            .parse()
            .unwrap_or_else(|_| panic!("no number after '{what}' in:\n{e}"))
    };
    let needed = mib_after("needs about ");
    let allowed = mib_after("at most ");
    let heap = mib_after("90% of the device's ");
    assert!(
        needed > allowed && allowed <= heap * 9 / 10 + 1 && allowed + 1 >= heap * 9 / 10,
        "{e}"
    );
}

/// The numeric options of `command` (`render`, `view` or `bench`): its own,
/// and the method parameters from its `--help`.
fn numeric_options(command: &str) -> Vec<String> {
    let own: &[&str] = match command {
        "render" => &[
            "width",
            "height",
            "rsm",
            "exposure",
            "time",
            "device",
            "frames",
            "spp",
            "seed",
            "fps",
            "orbit-light",
            "orbit-camera",
        ],
        "view" => &["width", "height", "rsm", "exposure", "time", "device"],
        _ => &[
            "width",
            "height",
            "rsm",
            "frames",
            "timing-frames",
            "device",
        ],
    };
    // Every method parameter that takes a number (`<N>`; choices and
    // switches take words), whichever heading --help lists it under.
    let mut options: Vec<String> = own.iter().map(|s| s.to_string()).collect();
    options.extend(
        isr::methods::all_params()
            .into_iter()
            .filter(|p| p.value_name() == "N")
            .map(|p| p.name().to_string()),
    );
    let help = Isr::new(command).arg("--help").succeeds().stdout;
    for o in &options {
        assert!(
            help.contains(&format!("--{o}")),
            "isr {command} --help lacks --{o}"
        );
    }
    assert!(options.len() > own.len() + 5, "{options:?}");
    options
}

/// Issue 29, item 12a: a value that starts with a minus sign but is not
/// written as clap's negative numbers (`-inf`, `-1e-5`, `-.5`) reaches the
/// option, whose own check then judges it, for every numeric option of
/// `render`, `view` and `bench`.
#[test]
fn every_numeric_option_takes_values_with_a_minus_sign() {
    let dir = temp_dir("opt-minus");
    for command in ["render", "view", "bench"] {
        for option in numeric_options(command) {
            // One small frame, were the value taken; no window system, so
            // a viewer that got that far stops.
            let small: &[(&str, &str)] = match command {
                "view" => &[],
                "render" => &[("width", "16"), ("height", "16"), ("rsm", "16")],
                _ => &[
                    ("scenes", "cornell"),
                    ("methods", "hisr"),
                    ("width", "16"),
                    ("height", "16"),
                    ("rsm", "16"),
                    ("frames", "1"),
                    ("timing-frames", "1"),
                ],
            };
            let mut isr = Isr::new(command)
                .in_dir(&dir)
                .env_remove("DISPLAY")
                .env_remove("WAYLAND_DISPLAY")
                .env_remove("WAYLAND_SOCKET");
            for (name, value) in small.iter().filter(|(name, _)| *name != option) {
                isr = isr.arg(format!("--{name}")).arg(value);
            }
            if command == "bench" {
                isr = isr.arg("--quick");
            }
            let ran = isr.arg(format!("--{option}")).arg("-inf").run();
            assert!(
                !ran.stderr.contains("unexpected argument"),
                "isr {}: -inf was read as an option:\n{}",
                ran.line,
                ran.stderr
            );
        }
    }
    // The forms clap does not take for negative numbers reach the value.
    for value in ["-1e-5", "-.5", "-1E+1"] {
        Isr::tiny(&dir).args(["--time", value]).succeeds();
    }
    // And the exposure's own check names it.
    let e = Isr::tiny(&dir).args(["--exposure", "-inf"]).fails();
    assert!(e.contains("--exposure") && e.contains("finite"), "{e}");
}

/// `name`'s render with `alone` and `--visibility none` says `warning`; with
/// `--visibility voxels` (the default) it says nothing of the kind.
fn warns_only_without_voxels(name: &str, alone: &[&str], warning: &str) {
    let dir = temp_dir(name);
    let ran = Isr::tiny(&dir)
        .args(alone)
        .args(["--visibility", "none"])
        .succeeds();
    assert!(ran.stderr.contains(warning), "{}", ran.stderr);
    let ran = Isr::tiny(&dir)
        .args(alone)
        .args(["--visibility", "voxels"])
        .succeeds();
    assert!(!ran.stderr.contains("no effect"), "{}", ran.stderr);
}

/// `--visibility-grid` without `--visibility voxels` is most likely a
/// forgotten `--visibility voxels`: the render runs and says the grid has
/// no effect; with the grid on, nothing is said.
#[test]
fn a_grid_without_voxel_visibility_is_named_as_having_no_effect() {
    warns_only_without_voxels(
        "grid-without-voxels",
        &["--method", "hisr", "--visibility-grid", "32"],
        "--visibility-grid 32 has no effect without --visibility voxels",
    );
}

/// The same for `--visibility-subcells`, alone and with the grid's size.
#[test]
fn subcells_without_voxel_visibility_are_named_as_having_no_effect() {
    warns_only_without_voxels(
        "subcells-without-voxels",
        &["--method", "hisr", "--visibility-subcells", "1"],
        "--visibility-subcells 1 has no effect without --visibility voxels",
    );
    warns_only_without_voxels(
        "grid-and-subcells-without-voxels",
        &["--method", "hisr", "--visibility-grid", "32", "--visibility-subcells", "2"],
        "--visibility-grid 32 and --visibility-subcells 2 have no effect without --visibility voxels",
    );
}

/// `--hisr-shared-visibility on` or `--hisr-shared-refine` without the grid
/// is said to do nothing; with it, nothing is said, and the default (on)
/// is not named where the grid is off.
#[test]
fn shared_visibility_without_the_grid_is_named_as_having_no_effect() {
    for (name, args) in [
        ("sharing-without-voxels", ["--hisr-shared-visibility", "on"]),
        ("refine-without-voxels", ["--hisr-shared-refine", "0.5"]),
    ] {
        warns_only_without_voxels(
            name,
            &[&["--method", "hisr"][..], &args].concat(),
            "has no effect without --visibility voxels, --hisr-shared-visibility on",
        );
    }
    let dir = temp_dir("sharing-default");
    let ran = Isr::tiny(&dir)
        .args(["--method", "hisr", "--visibility", "none"])
        .succeeds();
    assert!(!ran.stderr.contains("has no effect"), "{}", ran.stderr);
}
