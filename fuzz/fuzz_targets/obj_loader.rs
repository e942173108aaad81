//! libFuzzer over the OBJ loader (`isr::scene::obj_load::load_bytes`) and
//! what the renderer first does with a scene. The first byte picks the
//! mode: the rest of the input as the OBJ file itself, or as the bytes the
//! generators of `isr::scene::fuzzing` make an OBJ and its MTL library from
//! (the same generators as the stable property test, tests/fuzz_loader_obj.rs).
//! Files resolve in a temporary folder, under the default (safe) policy
//! and the budgets of `Limits::FUZZ`, so libFuzzer's memory limit flags
//! only allocations no budget accounts for. A loaded scene must pass
//! `fuzzing::check_scene`, an error `fuzzing::check_message`.
#![no_main]

use isr::scene::fuzzing::{self, Bytes};
use isr::scene::limits::Limits;
use isr::scene::obj_load::load_bytes;
use isr::scene::LoadOptions;
use libfuzzer_sys::fuzz_target;
use std::sync::Once;

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("isr-fuzz-obj-{}", std::process::id()));
    static FIXTURES: Once = Once::new();
    FIXTURES.call_once(|| {
        let _ = std::fs::create_dir_all(&dir);
        let _ = fuzzing::fixtures(&dir);
    });
    let case = if mode & 1 == 0 {
        fuzzing::Case {
            name: "scene.obj",
            bytes: rest.to_vec(),
            files: vec![("scene.obj", rest.to_vec())],
        }
    } else {
        fuzzing::obj_case(&mut Bytes::new(rest))
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
