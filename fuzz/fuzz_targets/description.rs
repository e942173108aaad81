//! libFuzzer over scene descriptions (`isr::scene::description::load_bytes`)
//! with the OBJ they name. The first byte picks the mode: the rest of the
//! input as the description's JSON (naming a quad beside it), or as the
//! bytes the generators of `isr::scene::fuzzing` make a description, its OBJ
//! and its MTL library from (the same generators as the stable property
//! test, tests/fuzz_loader_obj.rs). Budgets are `Limits::FUZZ`; a loaded
//! scene must pass `fuzzing::check_scene`, an error `fuzzing::check_message`.
#![no_main]

use isr::scene::description::load_bytes;
use isr::scene::fuzzing::{self, Bytes};
use isr::scene::limits::Limits;
use isr::scene::LoadOptions;
use libfuzzer_sys::fuzz_target;
use std::sync::Once;

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("isr-fuzz-desc-{}", std::process::id()));
    static FIXTURES: Once = Once::new();
    FIXTURES.call_once(|| {
        let _ = std::fs::create_dir_all(&dir);
        let _ = fuzzing::fixtures(&dir);
        let _ = std::fs::write(
            dir.join("quad.obj"),
            "v 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nf 1 2 3 4\n",
        );
    });
    let case = if mode & 1 == 0 {
        fuzzing::Case {
            name: "d.scene.json",
            bytes: rest.to_vec(),
            files: vec![],
        }
    } else {
        fuzzing::description_case(&mut Bytes::new(rest))
    };
    let Ok(path) = case.write(&dir) else { return };
    let options = LoadOptions {
        allow_outside_uris: false,
        limits: Limits::FUZZ,
    };
    match load_bytes(&path, &case.bytes, &options) {
        Ok(scene) => {
            if let Err(e) = fuzzing::check_scene(&scene, &Limits::FUZZ) {
                panic!("{e}");
            }
        }
        Err(e) => {
            if let Err(e) = fuzzing::check_message(&format!("{e:#}")) {
                panic!("{e}");
            }
        }
    }
});
