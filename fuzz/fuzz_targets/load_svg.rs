//! Arbitrary bytes as an SVG drawing: load_path must return Ok or Err,
//! never panic, hang or run out of memory.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pcpp::pipeline::load_path;

fuzz_target!(|data: &[u8]| {
    let _ = load_path(data, "fuzz.svg");
});
