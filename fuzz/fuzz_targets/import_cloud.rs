//! Arbitrary bytes as a point-cloud scan (issue 14): the first byte picks
//! the file name (.xyz, .csv, .pcd or a vertex-only .ply), the rest is the
//! file. import_mesh must return Ok or Err, never panic, hang or run out
//! of memory, through the readers and the triangulation.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pcpp::mesh::{import_mesh, ImportOptions};

fuzz_target!(|data: &[u8]| {
    let Some((&pick, file)) = data.split_first() else {
        return;
    };
    let name = ["fuzz.xyz", "fuzz.csv", "fuzz.pcd", "fuzz.ply"][usize::from(pick & 3)];
    // Bit 2: a maximum edge length from the next byte (0.01-2.56 mm).
    let mut options = ImportOptions::DEFAULT;
    if pick & 4 != 0 {
        options.max_edge_mm = file.first().map(|&b| f64::from(b) / 100.0 + 0.01);
    }
    let _ = import_mesh(file, name, &options);
});
