//! Arbitrary bytes as a .stl scan: import_mesh must return Ok or Err, never
//! panic, hang or run out of memory.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pcpp::mesh::{import_mesh, ImportOptions};

fuzz_target!(|data: &[u8]| {
    let _ = import_mesh(data, "fuzz.stl", &ImportOptions::DEFAULT);
});
