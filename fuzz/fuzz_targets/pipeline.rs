//! A whole job from arbitrary bytes: scan + SVG + a few parameter bytes
//! (layout in `src/lib.rs`) -> prepare_scan -> run_on, marlin dialect. It
//! must return Ok or Err, never panic, hang or run out of memory.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let case = pcpp_fuzz::decode(data);
    let _ = pcpp_fuzz::run(&case);
});
