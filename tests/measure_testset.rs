//! Mode identification on the independent test set (tests/data/klipper, written by
//! benches/reference/sweep_testset.py: sweeps as Klipper's resonance tester drives the toolhead,
//! through base-excited modal plants integrated exactly, with sensor noise and drift, written
//! as Klipper writes its three file kinds). Every case, every file kind, against issue 20's
//! targets: each mode within 1 % in frequency (or half a bin of a spectrum file, whichever is
//! larger) and 15 % in damping — and, since a user never knows how many modes there are,
//! with `maxModes` = the true count, one more, and the default 3: the modes found beyond the
//! true ones (spurious) are counted. Prints the tables (`cargo test --release --test
//! measure_testset -- --nocapture`).
#![cfg(not(target_arch = "wasm32"))]

use input_shaping::measure::identify::{
    identify, identify_spectrum, IdentifiedMode, IdentifyOptions, MAX_MODES,
};
use input_shaping::measure::recording::{parse_file, Parsed, RecordingOptions};
use input_shaping::measure::spectrum_file::{combine_spectra, SpectrumFile};
use serde_json::Value;
use std::path::Path;
mod common;
use common::Rng;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/klipper");

fn read(name: &str) -> Parsed {
    read_in(DIR, name)
}

fn read_in(dir: &str, name: &str) -> Parsed {
    let text = std::fs::read_to_string(Path::new(dir).join(name)).unwrap();
    parse_file(
        &text,
        &RecordingOptions {
            file_name: Some(name.to_string()),
            ..RecordingOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// A found mode: frequency, damping and their uncertainties.
type Found = (f64, f64, f64, f64);

/// `maxModes` from the true count.
type MaxModes = fn(usize) -> usize;

struct Row {
    case: String,
    kind: &'static str,
    truth: (f64, f64),
    found: Option<Found>,
    ok: bool,
}

/// What one `maxModes` setting gave over the whole set: a row per true mode, and the found
/// modes that are no true mode's nearest (spurious).
#[derive(Default)]
struct Tally {
    rows: Vec<Row>,
    spurious: Vec<(String, &'static str, Found)>,
}

impl Tally {
    fn within(&self) -> usize {
        self.rows.iter().filter(|r| r.ok).count()
    }

    /// Matches each true mode to the nearest found one and checks the targets; a found mode
    /// that is no true mode's nearest is spurious.
    fn check(
        &mut self,
        case: &str,
        kind: &'static str,
        truth: &[(f64, f64)],
        found: &[Found],
        half_bin: f64,
    ) {
        let mut matched = vec![false; found.len()];
        for &(f, z) in truth {
            let best = (0..found.len())
                .min_by(|&a, &b| (found[a].0 - f).abs().total_cmp(&(found[b].0 - f).abs()));
            if let Some(i) = best {
                matched[i] = true;
            }
            let best = best.map(|i| found[i]);
            let ok = best.is_some_and(|(ff, zz, _, _)| {
                (ff - f).abs() <= (0.01 * f).max(half_bin) && (zz - z).abs() <= 0.15 * z
            });
            self.rows.push(Row {
                case: case.to_string(),
                kind,
                truth: (f, z),
                found: best,
                ok,
            });
        }
        for (m, &fd) in matched.iter().zip(found) {
            if !m {
                self.spurious.push((case.to_string(), kind, fd));
            }
        }
    }

    /// The rows (only the misses when `only_failed`), then the count.
    fn print(&self, only_failed: bool) {
        self.print_rows(only_failed);
        println!(
            "{} of {} modes within the targets, {} spurious",
            self.within(),
            self.rows.len(),
            self.spurious.len()
        );
    }

    fn print_rows(&self, only_failed: bool) {
        println!(
            "{:<18} {:<12} {:>8} {:>6}   {:>8} {:>7} {:>7} {:>7}  ok",
            "case", "file", "f true", "ζ true", "f found", "±", "ζ found", "±"
        );
        for r in self.rows.iter().filter(|r| !(only_failed && r.ok)) {
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
        for (case, kind, (f, z, sf, sz)) in &self.spurious {
            println!(
                "{case:<18} {kind:<12} spurious          {f:>8.2} {sf:>7.2} {z:>7.4} {sz:>7.4}"
            );
        }
    }
}

fn found_of(modes: &[IdentifiedMode]) -> Vec<Found> {
    modes
        .iter()
        .map(|m| {
            (
                m.frequency_hz,
                m.damping,
                m.frequency_uncertainty_hz,
                m.damping_uncertainty,
            )
        })
        .collect()
}

/// The modes identified in one file (a spectrum file, or the raw recording's `axis` channel),
/// and half a bin of a spectrum file (0 for a recording).
fn identify_file(name: &str, file: &str, axis: &str, max_modes: usize) -> (Vec<Found>, f64) {
    identify_file_in(DIR, name, file, axis, max_modes)
}

fn identify_file_in(
    dir: &str,
    name: &str,
    file: &str,
    axis: &str,
    max_modes: usize,
) -> (Vec<Found>, f64) {
    let options = IdentifyOptions {
        max_modes,
        ..IdentifyOptions::new(f64::NAN)
    };
    match read_in(dir, file) {
        Parsed::Spectrum(s) => match identify_spectrum(&s, &options) {
            Ok(id) => (found_of(&id.modes), 0.5 * s.resolution_hz),
            Err(e) => {
                println!("{name} {file}: {e}");
                (Vec::new(), 0.5 * s.resolution_hz)
            }
        },
        Parsed::Recording(r) => {
            let x = &r.channel(&format!("accel_{axis}")).unwrap().values;
            let id = identify(
                x,
                &IdentifyOptions {
                    sample_rate_hz: r.sample_rate_hz,
                    free_decay: false,
                    ..options
                },
            )
            .unwrap();
            (found_of(&id.modes), 0.0)
        }
    }
}

/// Every case and file kind of the manifest, and two runs of one axis combined (Klipper's
/// add_data average), with `maxModes` = `max_modes(true count)`.
fn tally(manifest: &Value, max_modes: impl Fn(usize) -> usize) -> Tally {
    let mut t = tally_in(DIR, manifest, &max_modes);
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
            max_modes: max_modes(2).min(MAX_MODES),
            ..IdentifyOptions::new(f64::NAN)
        },
    )
    .unwrap();
    t.check(
        "x_m1 + x_m1run2",
        "combined",
        &[(42.0, 0.06), (71.0, 0.04)],
        &found_of(&id.modes),
        0.5 * combined[0].resolution_hz,
    );
    t
}

/// Every case and file kind of a manifest in `dir`.
fn tally_in(dir: &str, manifest: &Value, max_modes: &dyn Fn(usize) -> usize) -> Tally {
    let mut t = Tally::default();
    for (name, case) in manifest["cases"].as_object().unwrap() {
        let truth: Vec<(f64, f64)> = case["modes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| (m["f"].as_f64().unwrap(), m["zeta"].as_f64().unwrap()))
            .collect();
        let n = max_modes(truth.len()).clamp(1, MAX_MODES);
        let axis = case["axis"].as_str().unwrap();
        for (kind, key) in [
            ("resonances", "resonances"),
            ("calibration", "calibration_data"),
            ("raw", "raw"),
        ] {
            if let Some(file) = case["files"][key].as_str() {
                let (found, half_bin) = identify_file_in(dir, name, file, axis, n);
                t.check(name, kind, &truth, &found, half_bin);
            }
        }
    }
    t
}

#[test]
fn every_case_of_the_independent_test_set() {
    let manifest: Value = serde_json::from_str(
        &std::fs::read_to_string(Path::new(DIR).join("manifest.json")).unwrap(),
    )
    .unwrap();
    // The true count, one more, the default, the most (identify::MAX_MODES).
    let settings: [(&str, MaxModes); 4] = [
        ("maxModes = true count", |n| n),
        ("maxModes = true count + 1", |n| n + 1),
        ("maxModes = 3 (the default)", |_| 3),
        ("maxModes = 8 (the most)", |_| MAX_MODES),
    ];
    let mut summary = Vec::new();
    for (i, (label, max_modes)) in settings.iter().enumerate() {
        let t = tally(&manifest, max_modes);
        println!("\n{label}:");
        // The whole table for the true count, the misses and the spurious modes otherwise.
        t.print(i > 0);
        summary.push((label, t.within(), t.rows.len(), t.spurious.len()));
    }
    println!();
    for (label, within, rows, spurious) in &summary {
        println!("{label:<28} {within} of {rows} within the targets, {spurious} spurious");
    }
    // rigid133 has no mode under its sweep's end: a line between its last two bins, raising no
    // bin, was reported until a mode held back under the end had to raise the model at a bin
    // (1 spurious without that rule, at every setting).
    // Issue 20's target is every mode; today 62 of 65 meet it (three47r3022, a broad mode and
    // two sharp ones, whose joint fit fell into a minimum of 100 times the least sum from every
    // start until the physical start gave each mode its level under the excitation's slope;
    // 59 of 62 before it; swap63x100, a sharp mode under
    // a broad one 1.58 times higher, whose fitted modes the joint fit returned swapped between
    // their seeds: 62.99 Hz went to the broad peak's slot, 61.98 Hz was reported beside it and
    // 99.8 Hz lost, until each fitted mode went to the peak it lies on; 56 of 59 before it;
    // broad62sharp117, a broad mode
    // with a sharp one 1.88 times higher, read 64.9 / 0.23 and 116.1 / 0.034 until the joint
    // fit got a start with a base-excited structure's signs; the close pairs pair56x76 and
    // pair43x53, whose peaks 4-5 dB over the dip between them were read as one broad mode at
    // neither frequency until a broad mode was split on the humps under it; 48 of 51 before
    // them; 46 of 49 before the case
    // short36x123, whose start a spectrum file showed split over two bins, was added; 42 of
    // 45 before the case cliff133, 86a9f82; see docs/measured-data.md: the
    // slow machine's 1, 3.4 and 11 Hz modes from its resonances file — 13 bins of 1.95 Hz,
    // the sweep ending at 16 Hz — miss; its 1 Hz mode from the raw file, below the part of the
    // sweep whose spectrum is smooth, is met since the sweep's start peaks are fitted alone:
    // 41 before). This bound keeps what is met from regressing until the rest is; it is not
    // the target. A user does not know how many modes there
    // are: with more allowed than there are (one more, the default 3, the most), no mode may
    // be added that is not there, and the true ones must come out as well.
    for (label, within, rows, spurious) in &summary {
        assert!(
            *within >= 62,
            "{label}: {} of {rows} modes outside the targets (62 met when this bound was set)",
            rows - within
        );
        assert_eq!(*spurious, 0, "{label}: {spurious} spurious modes");
    }
}

/// Random machines (benches/reference/sweep_random.py: 1–3 modes, ζ 0.015–0.15, swept
/// 5–200 or 5–133.33 Hz through sweep_testset.py's time-domain model), not in the repository:
/// `python3 benches/reference/sweep_random.py DIR [N] [SEED]` then `SWEEP_RANDOM_DIR=DIR cargo
/// test --release --test measure_testset -- --ignored random --nocapture`. Prints the table
/// and the count within issue 20's targets (docs/measured-data.md); fails on a spurious mode.
#[test]
#[ignore = "needs SWEEP_RANDOM_DIR: files generated by benches/reference/sweep_random.py"]
fn random_machines() {
    let Ok(dir) = std::env::var("SWEEP_RANDOM_DIR") else {
        println!("SWEEP_RANDOM_DIR is not set: nothing to do");
        return;
    };
    let manifest: Value = serde_json::from_str(
        &std::fs::read_to_string(Path::new(&dir).join("manifest.json")).unwrap(),
    )
    .unwrap();
    let t = tally_in(&dir, &manifest, &|_| 3);
    t.print(false);
    assert_eq!(t.spurious.len(), 0, "spurious modes");
}

/// Gamma(k, 1/k): a Welch estimate's ratio to its expectation, k independent segments (the
/// mean of k unit exponentials).
fn welch_ratio(rng: &mut Rng, k: usize) -> f64 {
    (0..k).map(|_| -rng.uniform().ln()).sum::<f64>() / k as f64
}

/// I₀ by its series (Kaiser's window).
fn bessel_i0(x: f64) -> f64 {
    let (mut term, mut sum) = (1.0, 1.0);
    for k in 1..60 {
        term *= (0.5 * x / k as f64).powi(2);
        sum += term;
    }
    sum
}

/// A Klipper-like resonances file written here from closed forms, independently of the
/// identification code: the expected Welch PSD (symmetric Kaiser β = 6 of `nperseg` samples
/// at `fs`, its kernel |W(ν)|² summed over ±6 bins in steps of 1/16 bin) of a base-excited
/// accelerometer under Klipper's sweep, S(f) = f²·|1 − Σ gᵢ s²/(s² + 2ζᵢωᵢs + ωᵢ²)|² + B,
/// times Gamma(k, 1/k) noise per bin (k segments averaged). The sweep ends at `sweep_end_hz`
/// (`f64::INFINITY`: past the file's last row): the f²·|H|² term tapers (half cosine) over
/// its last 3 Hz to 1 % past it (as Klipper's releases of 2021–2023 show, which swept to
/// 133.33 Hz and wrote rows to 200 Hz).
fn synthetic_resonances(
    modes: &[(f64, f64, f64)],
    floor: f64,
    k: usize,
    sweep_end_hz: f64,
    rng: &mut Rng,
) -> String {
    let (fs, nperseg) = (3200.0, 2048usize);
    let df = fs / nperseg as f64;
    let m = nperseg - 1;
    let w: Vec<f64> = (0..nperseg)
        .map(|i| {
            let r = 2.0 * i as f64 / m as f64 - 1.0;
            bessel_i0(6.0 * (1.0 - r * r).max(0.0).sqrt()) / bessel_i0(6.0)
        })
        .collect();
    let sub = 16;
    let offsets: Vec<f64> = (-6 * sub..=6 * sub)
        .map(|j| j as f64 / sub as f64)
        .collect();
    let mut kern: Vec<f64> = offsets
        .iter()
        .map(|nu| {
            let (mut re, mut im) = (0.0, 0.0);
            for (i, wi) in w.iter().enumerate() {
                let ph = -2.0 * std::f64::consts::PI * nu * i as f64 / nperseg as f64;
                re += wi * ph.cos();
                im += wi * ph.sin();
            }
            re * re + im * im
        })
        .collect();
    let total: f64 = kern.iter().sum();
    kern.iter_mut().for_each(|v| *v /= total);
    let true_psd = |f: f64| {
        let f = f.abs();
        // The excitation's end as the real files show it (docs/measured-data.md: 10–30 dB
        // within 2–3 bins, then the level of what is left, harmonics and fans, 20 dB down):
        // a half-cosine taper over the last 3 Hz to 1 % of the sweep's power.
        let taper = if f >= sweep_end_hz {
            0.01
        } else if f > sweep_end_hz - 3.0 {
            let x = (sweep_end_hz - f) / 3.0;
            0.01 + 0.99 * 0.5 * (1.0 - (std::f64::consts::PI * x).cos())
        } else {
            1.0
        };
        let (mut hr, mut hi) = (1.0, 0.0);
        for &(fi, z, g) in modes {
            // s²/(s² + 2ζωs + ω²) at s = iω_f: −f²/(fi² − f² + 2iζ fi f).
            let (dr, di) = (fi * fi - f * f, 2.0 * z * fi * f);
            let d2 = dr * dr + di * di;
            hr += g * f * f * dr / d2;
            hi -= g * f * f * di / d2;
        }
        taper * f * f * (hr * hr + hi * hi) + floor
    };
    let mut text = String::from("freq,psd_x,psd_y,psd_z,psd_xyz\n");
    for bin in 0..=(300.0 / df) as usize {
        let f = bin as f64 * df;
        let expected: f64 = offsets
            .iter()
            .zip(&kern)
            .map(|(nu, c)| c * true_psd(f + nu * df))
            .sum();
        let x = expected * welch_ratio(rng, k);
        let (y, z) = (floor * welch_ratio(rng, k), floor * welch_ratio(rng, k));
        text.push_str(&format!(
            "{f:.1},{x:.3e},{y:.3e},{z:.3e},{:.3e}\n",
            x + y + z
        ));
    }
    text
}

/// The model order over many noise draws: resonances files written from closed forms (one to
/// three modes, ζ 0.01 to 0.15, a mode 4 dB weaker at a ratio 1.4; 20 and 80 Welch segments),
/// identified with `maxModes` = 8, the most: as many modes found as there are, none added,
/// and with 80 segments each within issue 20's targets.
/// A generated resonances file's text, parsed as the spectrum file it must be.
fn spectrum_of(text: &str, name: &str) -> SpectrumFile {
    let options = RecordingOptions {
        file_name: Some(name.to_string()),
        ..RecordingOptions::default()
    };
    match parse_file(text, &options).unwrap() {
        Parsed::Spectrum(spectrum) => spectrum,
        Parsed::Recording(_) => panic!("{name}: not a spectrum"),
    }
}

#[test]
fn no_spurious_modes_over_noise_draws() {
    let sets: [&[(f64, f64, f64)]; 4] = [
        &[(47.3, 0.08, 1.0)],
        &[(88.0, 0.01, 1.0)],
        &[(38.0, 0.04, 0.61), (53.2, 0.04, 0.39)],
        &[(32.0, 0.06, 0.34), (51.0, 0.03, 0.21), (87.0, 0.15, 0.45)],
    ];
    let (mut t20, mut t80, mut miscounted) = (Tally::default(), Tally::default(), Vec::new());
    let mut rng = Rng(20);
    for (s, modes) in sets.iter().enumerate() {
        let truth: Vec<(f64, f64)> = modes.iter().map(|m| (m.0, m.1)).collect();
        for k in [20, 80] {
            for draw in 0..3 {
                let text = synthetic_resonances(modes, 20.0, k, f64::INFINITY, &mut rng);
                let name = format!("resonances_x_set{s}_k{k}_{draw}.csv");
                let spectrum = spectrum_of(&text, &name);
                let id = identify_spectrum(
                    &spectrum,
                    &IdentifyOptions {
                        max_modes: MAX_MODES,
                        ..IdentifyOptions::new(f64::NAN)
                    },
                )
                .unwrap();
                let half_bin = 0.5 * spectrum.resolution_hz;
                if id.modes.len() != truth.len() {
                    miscounted.push(name.clone());
                }
                let tally = if k == 80 { &mut t80 } else { &mut t20 };
                tally.check(&name, "synthetic", &truth, &found_of(&id.modes), half_bin);
            }
        }
    }
    for (k, t) in [(20, &t20), (80, &t80)] {
        println!("\n{k} segments:");
        t.print(false);
        assert_eq!(t.spurious.len(), 0, "{k} segments: spurious modes");
    }
    assert!(
        miscounted.is_empty(),
        "not as many modes as there are: {miscounted:?}"
    );
    // With 80 segments (a 20 s test has 77 of Klipper's 0.5 s ones) every mode within the
    // targets; with 20 the noise alone moves some beyond them (their uncertainties say so).
    assert_eq!(
        t80.within(),
        t80.rows.len(),
        "80 segments: modes outside the targets"
    );
}

/// Three modes whose peaks stand a few dB over their neighbours' flanks (`sweep_random.py` seed
/// 52's machine r13, `--hard`: 32.38 Hz ζ 0.046, 44.3 Hz ζ 0.114, 62.35 Hz ζ 0.126, gains 0.19,
/// 0.34, 0.47), written from closed forms. Only the 62 Hz peak clears the 6 dB prominence; the
/// fit from it alone is one broad mode (64.5 Hz, ζ 0.23) over all three, and one mode added at a
/// time from there fell into a two-mode minimum with ζ 0.4 (refused) or off the humps. Every
/// local maximum left unseeded, tried at once (`model::bump_seeds`), finds all three within
/// issue 20's targets on each of three noise draws, and nothing more.
#[test]
fn modes_under_the_prominence_are_tried_together() {
    let modes = [
        (32.38, 0.0458, 0.1889),
        (44.3, 0.1142, 0.3369),
        (62.35, 0.1264, 0.4742),
    ];
    exactly_found_on_draws(&modes, f64::INFINITY, 52, "resonances_y_three");
}

/// Three noise draws (K = 400 segments, seeded by `seed`) of a resonances file written from
/// `modes` (frequency, ζ, gain) swept to `sweep_end_hz`: each read as exactly `modes.len()`
/// modes, every one within issue 20's targets, none spurious.
fn exactly_found_on_draws(modes: &[(f64, f64, f64)], sweep_end_hz: f64, seed: u64, name: &str) {
    let truth: Vec<(f64, f64)> = modes.iter().map(|m| (m.0, m.1)).collect();
    let mut tally = Tally::default();
    let mut rng = Rng(seed);
    for draw in 0..3 {
        let text = synthetic_resonances(modes, 20.0, 400, sweep_end_hz, &mut rng);
        let name = format!("{name}_{draw}.csv");
        let spectrum = spectrum_of(&text, &name);
        let id = identify_spectrum(&spectrum, &IdentifyOptions::new(f64::NAN)).unwrap();
        let found = found_of(&id.modes);
        assert_eq!(id.modes.len(), modes.len(), "{name}: {found:?}");
        let half_bin = 0.5 * spectrum.resolution_hz;
        tally.check(&name, "synthetic", &truth, &found, half_bin);
    }
    tally.print(false);
    assert_eq!(
        tally.within(),
        tally.rows.len(),
        "modes outside the targets"
    );
    assert!(tally.spurious.is_empty(), "spurious modes");
}

/// A seeded mode the fit trades for one found later (`sweep_random.py` seed 58's machine f10:
/// 83.77 Hz ζ 0.147 and 114.49 Hz ζ 0.048, gains 0.82 and 0.18, swept to 133.3 Hz at 4 Hz/s),
/// written from closed forms (K = 400). Only the 114.5 Hz peak is detected; its seed's fit
/// goes to the broad mode, a mode from the residuals then takes the 114.5 Hz peak, and the
/// seed's mode, on no peak, was dropped: one mode reported. Both are found within issue 20's
/// targets on each of three noise draws (`place_wandered` in identify/mod.rs), and nothing
/// more.
#[test]
fn a_seed_traded_for_a_mode_found_later_is_kept() {
    let modes = [(83.77, 0.1469, 0.8244), (114.49, 0.0482, 0.1756)];
    exactly_found_on_draws(&modes, 133.3, 58, "resonances_y_traded");
}

/// The sweep's end read as a mode (issue 20; docs/measured-data.md, *The end of the sweep*):
/// resonances files written from closed forms whose sweep ends at 133.3 Hz, as Klipper's
/// releases of 2021–2023 did (rows to 200 Hz), with a mode 15 Hz under the end (the response
/// high at the cliff: without the rule a lightly damped mode is fitted to the cliff's
/// shoulder) and, the guard, genuine modes 7 and 10 Hz under it, and a sharp one (ζ 0.015)
/// 5 Hz under it whose fall into the cliff is under 3 dB: every true mode is found within the
/// targets, none is reported at or past the cliff, and none is taken for a response cut off
/// there. `DRAWS=n` sets the noise draws per set (2; docs/measured-data.md gives 30).
#[test]
fn the_sweeps_end_is_not_a_mode() {
    let sets: [&[(f64, f64, f64)]; 4] = [
        &[(50.0, 0.06, 0.5), (118.0, 0.04, 0.5)],
        &[(126.0, 0.03, 1.0)],
        &[(45.0, 0.05, 0.6), (123.0, 0.03, 0.4)],
        &[(128.0, 0.015, 1.0)],
    ];
    let mut rng = Rng(133);
    let mut t = Tally::default();
    let mut at_cliff = Vec::new();
    for (s, modes) in sets.iter().enumerate() {
        let truth: Vec<(f64, f64)> = modes.iter().map(|m| (m.0, m.1)).collect();
        for draw in 0..std::env::var("DRAWS").map_or(2, |v| v.parse().unwrap()) {
            let text = synthetic_resonances(modes, 20.0, 80, 133.3, &mut rng);
            let name = format!("resonances_x_end{s}_{draw}.csv");
            let spectrum = spectrum_of(&text, &name);
            let id = identify_spectrum(&spectrum, &IdentifyOptions::new(f64::NAN)).unwrap();
            let found = found_of(&id.modes);
            // The sweep's end is seen (but a sharp mode falling into the cliff, the last set,
            // may hide it: its own fall is as steep), and a mode under it is not taken for one
            // cut off there.
            match id.sweep_end_hz {
                Some(end) => assert!((128.0..133.3).contains(&end), "{name}: sweep end {end}"),
                None => assert_eq!(s, 3, "{name}: the sweep's end not found"),
            }
            assert_eq!(id.cut_off, None, "{name}: {:?}", id.notes);
            at_cliff.extend(
                found
                    .iter()
                    .filter(|m| m.0 > 129.0)
                    .map(|m| (name.clone(), m.0, m.1)),
            );
            t.check(
                &name,
                "synthetic",
                &truth,
                &found,
                0.5 * spectrum.resolution_hz,
            );
        }
    }
    t.print_rows(false);
    assert!(
        at_cliff.is_empty(),
        "modes at the sweep's end: {at_cliff:?}"
    );
    assert_eq!(t.spurious.len(), 0, "spurious modes");
    assert_eq!(t.within(), t.rows.len(), "modes outside the targets");
    // The generated file (benches/reference/sweep_testset.py, case cliff133: Klipper's sweep
    // 5–133.33 Hz simulated, modes at 45 and 123 Hz): nothing at the cliff either.
    for file in [
        "resonances_x_cliff133.csv",
        "calibration_data_x_cliff133.csv",
    ] {
        let (found, half_bin) = identify_file("x_cliff133", file, "x", MAX_MODES);
        let mut t = Tally::default();
        t.check(
            "x_cliff133",
            "file",
            &[(45.0, 0.05), (123.0, 0.03)],
            &found,
            half_bin,
        );
        t.print_rows(false);
        assert!(found.iter().all(|m| m.0 < 129.0), "{file}: {found:?}");
        assert_eq!(t.within(), 2, "{file}: {found:?}");
    }
}

/// A response cut off by the sweep's end (issue 20; a real Voron 0 file, bassco_v0_resonances_x,
/// rises to Klipper's 133.33 Hz and came out as "no mode"): resonances files written from
/// closed forms whose sweep ends at 133.3 Hz with the strongest mode above it. The mode is not
/// invented (no mode at or past the cliff), the response is reported as cut off at the last
/// fitted bin with a note for the user, and a mode under the end is still found within the
/// targets — also with a sharp mode (ζ 0.03) 4.7 Hz past the end, whose flank rises 8 dB over
/// the last 5 bins (the time-domain case c6 of benches/reference/sweep_cutoff_cases.py).
/// `DRAWS=n` sets the noise draws per set (6; docs/measured-data.md gives 30).
#[test]
fn a_response_cut_off_by_the_sweeps_end_is_reported() {
    // (the modes (f, ζ, gain), the true modes under the sweep's end)
    type Case = (&'static [(f64, f64, f64)], &'static [(f64, f64)]);
    let sets: [Case; 3] = [
        (&[(60.0, 0.05, 0.5), (142.0, 0.04, 0.5)], &[(60.0, 0.05)]),
        (&[(150.0, 0.05, 1.0)], &[]),
        (&[(72.0, 0.1, 0.5), (138.0, 0.03, 0.5)], &[(72.0, 0.1)]),
    ];
    let mut rng = Rng(134);
    for (s, (modes, truth)) in sets.iter().enumerate() {
        for draw in 0..std::env::var("DRAWS").map_or(6, |v| v.parse().unwrap()) {
            let text = synthetic_resonances(modes, 20.0, 80, 133.3, &mut rng);
            let name = format!("resonances_x_above{s}_{draw}.csv");
            let spectrum = spectrum_of(&text, &name);
            let id = identify_spectrum(&spectrum, &IdentifyOptions::new(f64::NAN)).unwrap();
            let found = found_of(&id.modes);
            let cut = id.cut_off.unwrap_or_else(|| {
                panic!(
                    "{name}: no cut-off (sweep end {:?}): {found:?}",
                    id.sweep_end_hz
                )
            });
            let end = id.sweep_end_hz.expect("the sweep's end");
            assert_eq!(cut.frequency_hz, end, "{name}");
            assert!((128.0..133.3).contains(&end), "{name}: sweep end {end}");
            assert!(cut.prominence_db >= 6.0, "{name}: {cut:?}");
            assert_eq!(id.notes.len(), 1, "{name}: {:?}", id.notes);
            assert!(
                id.notes[0].contains("higher maximum frequency"),
                "{:?}",
                id.notes
            );
            assert!(found.iter().all(|m| m.0 < 125.0), "{name}: {found:?}");
            let mut t = Tally::default();
            t.check(
                &name,
                "synthetic",
                truth,
                &found,
                0.5 * spectrum.resolution_hz,
            );
            t.print_rows(false);
            assert_eq!(t.spurious.len(), 0, "{name}: spurious modes");
            assert_eq!(t.within(), truth.len(), "{name}: {found:?}");
        }
    }
}

/// A stiff machine's files (`rigid133`: no mode under the sweep's end at 133.33 Hz, the PSD
/// rising as the drive's f² into it) report no mode and say that the response still rises at
/// the end. The resonances file reported a line between its last two bins, 130.45 Hz with
/// ζ 0.00001, until a mode fitted back under the end had to raise the model at a fitted bin.
/// The rise is reported at the last bin fitted before the cliff, 131.25 Hz (bins of 1.5625 Hz;
/// the sweep ends at 133.33 Hz), with a note that says it may be the excitation's alone.
#[test]
fn a_file_without_modes_reports_none() {
    for file in [
        "resonances_y_rigid133.csv",
        "calibration_data_y_rigid133.csv",
    ] {
        let Parsed::Spectrum(s) = read(file) else {
            panic!("{file}: not a spectrum");
        };
        let id = identify_spectrum(&s, &IdentifyOptions::new(f64::NAN)).unwrap();
        assert!(id.modes.is_empty(), "{file}: {:?}", id.modes);
        let cut = id.cut_off.expect("the rise into the end is reported");
        assert!((cut.frequency_hz - 131.2).abs() < 2.0, "{file}: {cut:?}");
        // The note says the rise may be the excitation's alone (no mode under the end).
        assert_eq!(id.notes.len(), 1, "{file}: {:?}", id.notes);
        assert!(
            id.notes[0].contains("no mode was found under it")
                && id.notes[0].contains("the rise is the excitation's own")
                && id.notes[0].contains("higher maximum frequency"),
            "{file}: {}",
            id.notes[0]
        );
    }
}

/// No spectrum file of the test set says its response is cut off by the sweep's end: every
/// true mode lies under its sweep's end by more than its half-power width (the guard of
/// `a_response_cut_off_by_the_sweeps_end_is_reported`; short sweeps such as 38–56 Hz around
/// a 47.3 Hz mode included). Not `rigid133`, which has no mode under its end: its PSD rises
/// as the drive's f² into the end, and that is what the note says (a mode past the end cannot
/// be ruled out from such a file; its test is `a_file_without_modes_reports_none`).
#[test]
fn no_file_of_the_test_set_is_cut_off() {
    let manifest: Value = serde_json::from_str(
        &std::fs::read_to_string(Path::new(DIR).join("manifest.json")).unwrap(),
    )
    .unwrap();
    let mut files = 0;
    for case in manifest["cases"].as_object().unwrap().values() {
        if case["modes"].as_array().unwrap().is_empty() {
            continue;
        }
        for key in ["resonances", "calibration_data"] {
            let Some(file) = case["files"][key].as_str() else {
                continue;
            };
            let Parsed::Spectrum(s) = read(file) else {
                panic!("{file}: not a spectrum");
            };
            let id = identify_spectrum(&s, &IdentifyOptions::new(f64::NAN)).unwrap();
            assert_eq!(id.cut_off, None, "{file}: {:?}", id.notes);
            assert!(id.notes.is_empty(), "{file}: {:?}", id.notes);
            files += 1;
        }
    }
    assert!(files >= 20, "{files} spectrum files");
}
