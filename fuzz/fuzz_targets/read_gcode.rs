//! Arbitrary bytes as a G-code program, decoded lossily as `pcpp check`
//! reads a file: read_gcode must return Ok or Err, never panic, hang or run
//! out of memory.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pcpp::gcode::read_gcode;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let _ = read_gcode(&text, "fuzz.gcode");
});
