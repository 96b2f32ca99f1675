//! libFuzzer target: arbitrary bytes as a JSON spec (design, simulation or spectrum), parsed
//! and, when it parses, run. Any panic is a bug (the function panics on an invalid `Ok`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    input_shaping_fuzz::spec(data);
});
