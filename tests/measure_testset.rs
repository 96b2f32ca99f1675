//! Mode identification on the independent test set (tests/data/klipper, written by
//! benches/reference/sweep_testset.py: sweeps as Klipper's resonance tester drives the toolhead,
//! through base-excited modal plants integrated exactly, with sensor noise and drift, written
//! as Klipper writes its three file kinds). Every case, every file kind, against issue 20's
//! targets: each mode within 1 % in frequency (or half a bin of a spectrum file, whichever is
//! larger) and 15 % in damping. Prints the table (`cargo test --test measure_testset --
//! --nocapture`).
#![cfg(not(target_arch = "wasm32"))]

use input_shaping::measure::identify::{identify, identify_spectrum, IdentifyOptions};
use input_shaping::measure::recording::{parse_file, Parsed, RecordingOptions};
use input_shaping::measure::spectrum_file::combine_spectra;
use serde_json::Value;
use std::path::Path;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/klipper");

fn read(name: &str) -> Parsed {
    let text = std::fs::read_to_string(Path::new(DIR).join(name)).unwrap();
    parse_file(
        &text,
        &RecordingOptions {
            file_name: Some(name.to_string()),
            ..RecordingOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

struct Row {
    case: String,
    kind: &'static str,
    truth: (f64, f64),
    found: Option<(f64, f64, f64, f64)>,
    ok: bool,
}

/// Matches each true mode to the nearest found one and checks the targets.
fn check(
    case: &str,
    kind: &'static str,
    truth: &[(f64, f64)],
    found: &[(f64, f64, f64, f64)],
    half_bin: f64,
    rows: &mut Vec<Row>,
) {
    for &(f, z) in truth {
        let best = found
            .iter()
            .min_by(|a, b| (a.0 - f).abs().total_cmp(&(b.0 - f).abs()))
            .copied();
        let ok = best.is_some_and(|(ff, zz, _, _)| {
            (ff - f).abs() <= (0.01 * f).max(half_bin) && (zz - z).abs() <= 0.15 * z
        });
        rows.push(Row {
            case: case.to_string(),
            kind,
            truth: (f, z),
            found: best,
            ok,
        });
    }
}

#[test]
fn every_case_of_the_independent_test_set() {
    let manifest: Value = serde_json::from_str(
        &std::fs::read_to_string(Path::new(DIR).join("manifest.json")).unwrap(),
    )
    .unwrap();
    let cases = manifest["cases"].as_object().unwrap();
    let mut rows = Vec::new();
    for (name, case) in cases {
        let truth: Vec<(f64, f64)> = case["modes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| (m["f"].as_f64().unwrap(), m["zeta"].as_f64().unwrap()))
            .collect();
        // The number of modes is given (with one more allowed, the residual search adds
        // spurious modes on these files: see docs/measured-data.md).
        let max_modes = truth.len().min(8);
        let files = &case["files"];
        for (kind, key) in [
            ("resonances", "resonances"),
            ("calibration", "calibration_data"),
            ("raw", "raw"),
        ] {
            let Some(file) = files[key].as_str() else {
                continue;
            };
            let options = IdentifyOptions {
                max_modes,
                ..IdentifyOptions::new(f64::NAN)
            };
            let (found, half_bin) = match read(file) {
                Parsed::Spectrum(s) => match identify_spectrum(&s, &options) {
                    Ok(id) => (id.modes, 0.5 * s.resolution_hz),
                    Err(e) => {
                        println!("{name} {kind}: {e}");
                        (Vec::new(), 0.5 * s.resolution_hz)
                    }
                },
                Parsed::Recording(r) => {
                    let x = &r
                        .channel(&format!("accel_{}", case["axis"].as_str().unwrap()))
                        .unwrap()
                        .values;
                    let id = identify(
                        x,
                        &IdentifyOptions {
                            sample_rate_hz: r.sample_rate_hz,
                            free_decay: false,
                            ..options.clone()
                        },
                    )
                    .unwrap();
                    (id.modes, 0.0)
                }
            };
            let found: Vec<(f64, f64, f64, f64)> = found
                .iter()
                .map(|m| {
                    (
                        m.frequency_hz,
                        m.damping,
                        m.frequency_uncertainty_hz,
                        m.damping_uncertainty,
                    )
                })
                .collect();
            check(name, kind, &truth, &found, half_bin, &mut rows);
        }
    }
    // Two runs of one axis combined (Klipper's add_data average).
    let a = match read("resonances_x_m1.csv") {
        Parsed::Spectrum(s) => s,
        _ => unreachable!(),
    };
    let b = match read("resonances_x_m1run2.csv") {
        Parsed::Spectrum(s) => s,
        _ => unreachable!(),
    };
    let combined = combine_spectra(&[a, b]).unwrap();
    assert_eq!(combined.len(), 1);
    assert_eq!(combined[0].sources, 2);
    let id = identify_spectrum(
        &combined[0],
        &IdentifyOptions {
            max_modes: 2,
            ..IdentifyOptions::new(f64::NAN)
        },
    )
    .unwrap();
    let found: Vec<_> = id
        .modes
        .iter()
        .map(|m| {
            (
                m.frequency_hz,
                m.damping,
                m.frequency_uncertainty_hz,
                m.damping_uncertainty,
            )
        })
        .collect();
    check(
        "x_m1 + x_m1run2",
        "combined",
        &[(42.0, 0.06), (71.0, 0.04)],
        &found,
        0.5 * combined[0].resolution_hz,
        &mut rows,
    );
    println!(
        "{:<18} {:<12} {:>8} {:>6}   {:>8} {:>7} {:>7} {:>7}  ok",
        "case", "file", "f true", "ζ true", "f found", "±", "ζ found", "±"
    );
    for r in &rows {
        match r.found {
            Some((f, z, sf, sz)) => println!(
                "{:<18} {:<12} {:>8.2} {:>6.3}   {:>8.2} {:>7.2} {:>7.4} {:>7.4}  {}",
                r.case,
                r.kind,
                r.truth.0,
                r.truth.1,
                f,
                sf,
                z,
                sz,
                if r.ok { "yes" } else { "NO" }
            ),
            None => println!(
                "{:<18} {:<12} {:>8.2} {:>6.3}   (none found)  NO",
                r.case, r.kind, r.truth.0, r.truth.1
            ),
        }
    }
    let failed = rows.iter().filter(|r| !r.ok).count();
    println!(
        "{} of {} modes within the targets",
        rows.len() - failed,
        rows.len()
    );
    // Issue 20's target is every mode; today 41 of 45 meet it (see docs/measured-data.md: the
    // slow machine's 1, 3.4 and 11 Hz modes from its resonances file — 13 bins of 1.95 Hz,
    // the sweep ending at 16 Hz — and its 1 Hz mode from the raw file, below the part of the
    // sweep whose spectrum is smooth, miss). This bound keeps what is met from regressing
    // until the rest is; it is not the target.
    assert!(
        rows.len() - failed >= 41,
        "{failed} of {} modes outside the targets (41 met when this bound was set)",
        rows.len()
    );
}
