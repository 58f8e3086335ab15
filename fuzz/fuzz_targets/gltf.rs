//! Fuzzes `Scene::load` on a `.gltf` or `.glb` file, as `ssm render --scene FILE` loads it.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    // Errors are the expected outcome of most inputs; panics, hangs and running out of memory are the bugs.
    let _ = ssm_scene::fuzzing::load(ssm_scene::fuzzing::Target::Gltf, data);
});
