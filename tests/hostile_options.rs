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
