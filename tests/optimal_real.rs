//! Issue 25 on real Klipper files that are not in the repository (their licences are unknown;
//! sources in benches/real_klipper_sources.md): `REAL_KLIPPER_DIR=/path cargo test --release
//! --test optimal_real -- --ignored --nocapture`. Each file is read by the product's reader
//! (`parse_file`), its modes identified (`identify_spectrum`, default options), and for each the
//! table prints Klipper's pick, the best mainline shaper and the best custom shaper
//! (RepRapFirmware limits) with and without the modes, which constraint is active at the
//! optimum, the continuation against the grid program (`both`) and the R = 0 floor of the
//! convex program (`no_vibration_bound`). Prints only: the figures go to
//! docs/measured-data.md (*On real recordings*).

use input_shaping::measure::identify::{identify_spectrum, IdentifyOptions};
use input_shaping::measure::klipper::CalibrationData;
use input_shaping::measure::optimal::{
    optimal, CustomMethod, Firmware, OptimalOptions, OptimalReport, VIBRATION_ALLOWANCE,
};
use input_shaping::measure::recommend::{calibration_data, MeasuredMode, MeasuredSpectrum};
use input_shaping::measure::recording::{parse_file, Parsed};
use input_shaping::measure::RecordingOptions;

/// The calibration data and identified modes of one real file.
fn load(path: &std::path::Path) -> (CalibrationData, Vec<MeasuredMode>) {
    let text = std::fs::read_to_string(path).unwrap();
    let Parsed::Spectrum(sf) = parse_file(&text, &RecordingOptions::default()).unwrap() else {
        panic!("{path:?} is not a spectrum file");
    };
    let id = identify_spectrum(&sf, &IdentifyOptions::default()).unwrap();
    let modes = id
        .modes
        .iter()
        .map(|m| MeasuredMode {
            frequency_hz: m.frequency_hz,
            damping: m.damping,
            frequency_uncertainty_hz: m.frequency_uncertainty_hz,
            damping_uncertainty: m.damping_uncertainty,
        })
        .collect();
    let spectrum = MeasuredSpectrum {
        frequency_hz: sf.frequency_hz.clone(),
        psd: sf.psd.clone(),
        normalization: sf.normalization,
        ..MeasuredSpectrum::default()
    };
    (calibration_data(&spectrum).unwrap(), modes)
}

/// The smallest last amplitudes of the R = 0 floor: `FLOOR_MINIMA` (comma-separated), by
/// default the optimiser's 2 % rule and none. The floors need the solver.
#[cfg(feature = "solver")]
fn floor_minima() -> Vec<f64> {
    std::env::var("FLOOR_MINIMA").map_or_else(
        |_| vec![input_shaping::measure::optimal::MIN_CUSTOM_AMPLITUDE, 0.0],
        |s| s.split(',').map(|x| x.trim().parse().unwrap()).collect(),
    )
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    0.5 * (v[(n - 1) / 2] + v[n / 2])
}

/// Which of the custom search's constraints is within 1 % of its bound at the result.
fn active(r: &OptimalReport) -> String {
    let (pick, main, custom) = (&r.rows[0], &r.rows[1], &r.rows[2]);
    let mut out = Vec::new();
    let r_bound = pick.klipper.vibrations.max(VIBRATION_ALLOWANCE);
    if custom.klipper.vibrations >= 0.99 * r_bound {
        out.push("Klipper's R");
    }
    if custom.robust_vibrations >= 0.99 * pick.robust_vibrations.max(VIBRATION_ALLOWANCE) {
        out.push("robust R");
    }
    if custom.klipper.score >= 0.9999 * main.klipper.score {
        out.push("≤ mainline");
    }
    if out.is_empty() {
        "none".into()
    } else {
        out.join(", ")
    }
}

#[test]
#[ignore = "needs REAL_KLIPPER_DIR (files not in the repository)"]
fn real_files_table() {
    let Ok(dir) = std::env::var("REAL_KLIPPER_DIR") else {
        return;
    };
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".csv"))
        .collect();
    names.sort();
    let methods: Vec<(&str, CustomMethod)> = match std::env::var("OPTIMAL_METHOD").as_deref() {
        Ok("both") => vec![
            ("continuation", CustomMethod::Continuation),
            ("both", CustomMethod::Both),
        ],
        _ => vec![("continuation", CustomMethod::Continuation)],
    };
    let mut gains: Vec<(String, Vec<f64>)> = Vec::new();
    let skip = std::env::var("FLOOR_ONLY").is_ok();
    for name in &names {
        let (data, modes) = load(&std::path::Path::new(&dir).join(name));
        println!("{name}: {} modes", modes.len());
        for (with, m) in [("modes", &modes[..]), ("no modes", &[][..])] {
            if skip {
                break;
            }
            for &(label, method) in &methods {
                let t0 = std::time::Instant::now();
                let r = optimal(
                    &data,
                    m,
                    &OptimalOptions {
                        firmware: Firmware::Reprapfirmware,
                        custom_method: method,
                        ..OptimalOptions::default()
                    },
                )
                .unwrap();
                let ms = t0.elapsed().as_secs_f64() * 1e3;
                let (p, ml, c) = (&r.rows[0], &r.rows[1], &r.rows[2]);
                println!(
                    "  {with:8} {label:12} pick {:.6} R {:.2}% rR {:.2}% | main {} {:+.1}% | \
                     custom {} imp {:.6} {:+.1}% R {:.2}% rR {:.2}% sm {:.4} dur {:.1} ms | \
                     active: {} | {ms:.0} ms",
                    p.klipper.score,
                    100.0 * p.klipper.vibrations,
                    100.0 * p.robust_vibrations,
                    ml.family,
                    -100.0 * ml.improvement,
                    c.shaper.impulses.len(),
                    c.klipper.score,
                    -100.0 * c.improvement,
                    100.0 * c.klipper.vibrations,
                    100.0 * c.robust_vibrations,
                    c.klipper.smoothing,
                    1e3 * c.shaper.duration,
                    active(&r)
                );
                let key = format!("{with} {label}");
                let g = match gains.iter_mut().find(|(k, _)| *k == key) {
                    Some(g) => g,
                    None => {
                        gains.push((key.clone(), Vec::new()));
                        gains.last_mut().unwrap()
                    }
                };
                g.1.push(c.improvement);
            }
        }
        #[cfg(feature = "solver")]
        for last_min in floor_minima() {
            use input_shaping::measure::optimal::no_vibration_bound;
            let pick = optimal(&data, &[], &OptimalOptions::default())
                .unwrap()
                .rows[0]
                .klipper
                .score;
            if let Some(b) = no_vibration_bound(&data, 5.0, last_min).unwrap() {
                println!(
                    "  floor (R = 0, last ≥ {last_min}): {:.6} ({:+.1} %), {} imp., smallest \
                     {:.3}, {:.1} ms",
                    b.score,
                    100.0 * (b.score / pick - 1.0),
                    b.impulses,
                    b.smallest_amplitude,
                    1e3 * b.duration_s
                );
                let key = format!("floor last ≥ {last_min}");
                match gains.iter_mut().find(|(k, _)| *k == key) {
                    Some(g) => g.1.push(1.0 - b.score / pick),
                    None => gains.push((key, vec![1.0 - b.score / pick])),
                }
            }
        }
    }
    for (k, v) in &mut gains {
        println!("median {k}: {:+.1} %", -100.0 * median(v));
    }
}
