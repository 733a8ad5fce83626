//! Arbitrary bytes as a .gltf and as a .glb scan: import_mesh must return
//! Ok or Err, never panic, hang or run out of memory; so must listing its
//! external files and reading it with one (its own bytes as `fuzz.bin`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use pcpp::mesh::{
    external_files_needed, import_mesh, import_mesh_with, ExternalFiles, ImportOptions,
};

fuzz_target!(|data: &[u8]| {
    let _ = import_mesh(data, "fuzz.gltf", &ImportOptions::DEFAULT);
    let _ = import_mesh(data, "fuzz.glb", &ImportOptions::DEFAULT);
    let _ = external_files_needed(data, "fuzz.gltf");
    let bin = ExternalFiles::new().with("fuzz.bin", data.to_vec());
    let _ = import_mesh_with(data, "fuzz.gltf", &ImportOptions::DEFAULT, &bin);
});
