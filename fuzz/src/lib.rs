//! The fuzzed function (issue 6): bytes → JSON spec → design / simulation / spectrum.
//!
//! Used by the cargo-fuzz target `spec` (nightly, `fuzz_targets/spec.rs`) and, on stable, by
//! the main crate's `tests/fuzz_replay.rs`, which includes this file by `#[path]` and feeds it
//! the seed corpus and random inputs. Every input must give `Ok` or a typed error; a panic
//! (from the library, or from the checks below on an `Ok` result) is the bug the fuzzer
//! reports.

use input_shaping::scenario::SimulationSpec;
use input_shaping::scenario::SpectrumSpec;
use input_shaping::{DesignRequest, Shaper};

/// Panics unless `shaper` is a valid shaper: impulses present, finite, strictly increasing in
/// time, the first at t = 0.
pub fn assert_valid(shaper: &Shaper, input: &str) {
    let imps = shaper.impulses();
    assert!(!imps.is_empty(), "empty shaper for {input}");
    assert_eq!(imps[0].time, 0.0, "first impulse not at 0 for {input}");
    for w in imps.windows(2) {
        assert!(w[0].time < w[1].time, "times not increasing for {input}");
    }
    for i in imps {
        assert!(
            i.time.is_finite() && i.amplitude.is_finite(),
            "non-finite impulse {i:?} for {input}"
        );
    }
}

/// Parses `data` as a design request, a simulation spec and a spectrum spec; runs whatever
/// parses. Errors are fine (they are typed by construction: `input_shaping::Error`) but must
/// carry a message.
pub fn spec(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // Keep single inputs bounded: the library bounds sizes itself, this only keeps the
    // fuzzer's iterations fast.
    if text.len() > 20_000 {
        return;
    }
    if let Ok(request) = serde_json::from_str::<DesignRequest>(text) {
        match input_shaping::design(&request) {
            Ok(shaper) => assert_valid(&shaper, text),
            Err(e) => assert!(!e.to_string().is_empty(), "empty error for {text}"),
        }
    }
    if let Ok(sim) = serde_json::from_str::<SimulationSpec>(text) {
        match input_shaping::scenario::run(&sim) {
            Ok(r) => assert_eq!(r.time.len(), r.unshaped.trajectory.endpoint.len()),
            Err(e) => assert!(!e.to_string().is_empty(), "empty error for {text}"),
        }
    }
    if let Ok(spectrum) = serde_json::from_str::<SpectrumSpec>(text) {
        match input_shaping::scenario::spectrum_for(&spectrum) {
            Ok(r) => assert_eq!(r.magnitude.len(), r.frequency_hz.len()),
            Err(e) => assert!(!e.to_string().is_empty(), "empty error for {text}"),
        }
    }
}
