//! Issue 24's faster polish and search (`solve::set_reference_polish(false)`, the default)
//! against the previous ones (`true`) on solved designs: the same or a shorter duration, and
//! V ≤ Vtol verified here independently of the library's own scan, on a dense grid over every
//! band (200 points per band, eq. 11 through `vibration_rad`).
//!
//! One test function: the switch is process-wide, so nothing else may run in this binary.

use input_shaping::vibration::vibration_rad;
use input_shaping::{design, DesignRequest};
use std::f64::consts::PI;

/// (name, spec JSON, modes (Hz, ζ), insensitivity I, Vtol) — the band of a mode is
/// f(1 ± I/2); `None`: no band (equality constraints only).
type Case = (&'static str, &'static str, Option<(f64, f64)>);

const CASES: &[Case] = &[
    (
        "si 1 mode I 0.7 (Peláez & Singhose)",
        r#"{"family":"si","modes":[{"frequencyHz":0.5,"damping":0.002}],"vtol":0.05,"insensitivity":0.7}"#,
        Some((0.7, 0.05)),
    ),
    (
        "si 2 modes I 0.4",
        r#"{"family":"si","modes":[{"frequencyHz":2,"damping":0.05},{"frequencyHz":5.5,"damping":0.02}],"vtol":0.05,"insensitivity":0.4}"#,
        Some((0.4, 0.05)),
    ),
    (
        "si 3 modes I 0.3",
        r#"{"family":"si","modes":[{"frequencyHz":1.2,"damping":0.02},{"frequencyHz":3.4,"damping":0.02},{"frequencyHz":7.9,"damping":0.02}],"vtol":0.05,"insensitivity":0.3}"#,
        Some((0.3, 0.05)),
    ),
    (
        "si 3 modes I 0.5 vtol 0.1",
        r#"{"family":"si","modes":[{"frequencyHz":1.2,"damping":0.02},{"frequencyHz":3.4,"damping":0.02},{"frequencyHz":7.9,"damping":0.02}],"vtol":0.1,"insensitivity":0.5}"#,
        Some((0.5, 0.1)),
    ),
    (
        "direct ZVD 3 modes",
        r#"{"family":"direct","modes":[{"frequencyHz":1.2,"damping":0.02},{"frequencyHz":3.4,"damping":0.02},{"frequencyHz":7.9,"damping":0.02}]}"#,
        None,
    ),
];

fn request(json: &str) -> DesignRequest {
    serde_json::from_str(json).expect("spec")
}

/// The largest V/Vtol over the bands f(1 ± I/2) of every mode, at the mode's damping.
fn worst_ratio(shaper: &input_shaping::Shaper, req: &DesignRequest, i: f64, vtol: f64) -> f64 {
    let mut worst = 0.0_f64;
    for m in &req.modes {
        for k in 0..=200 {
            let f = m.frequency_hz * (1.0 - i / 2.0 + i * k as f64 / 200.0);
            let v = vibration_rad(shaper.impulses(), 2.0 * PI * f, m.damping);
            worst = worst.max(v / vtol);
        }
    }
    worst
}

#[test]
fn faster_polish_same_or_shorter_and_within_vtol() {
    let mut rows = Vec::new();
    for &(name, json, band) in CASES {
        let req = request(json);
        input_shaping::solve::set_reference_polish(true);
        let old = design(&req).expect("reference design");
        input_shaping::solve::set_reference_polish(false);
        let new = design(&req).expect("design");
        if let Some((i, vtol)) = band {
            let r = worst_ratio(&new, &req, i, vtol);
            assert!(r <= 1.0 + 1e-8, "{name}: V/Vtol = {r} on the band");
        }
        rows.push(format!(
            "| {name} | {:.6} s, {} | {:.6} s, {} |",
            old.duration(),
            old.len(),
            new.duration(),
            new.len()
        ));
        assert!(
            new.duration() <= old.duration() * (1.0 + 1e-9),
            "{name}: {} s now, {} s before",
            new.duration(),
            old.duration()
        );
    }
    println!(
        "| case | before | after |\n| --- | --- | --- |\n{}",
        rows.join("\n")
    );
}
