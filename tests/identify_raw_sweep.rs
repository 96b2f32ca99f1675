//! Issue 20: raw sweep recordings whose sweep ends at or before a mode. Klipper's resonance
//! test stops at its `max_freq` (133.33 Hz in its 2021–2023 releases); a stiff axis's mode at
//! or past it is rung only by the sweep's last seconds. Read as a spectrum file, such a response
//! is reported as cut off (tests/measure_testset.rs); a raw recording must be too — no mode made
//! up from its rising flank, the modes inside the band still right. And short, fast sweeps
//! (1.5–4 s), which the sweep detector's one-second frames did not see.
//!
//! The recordings are simulated here, independently of the identification code: Klipper's test
//! drive (klippy/extras/resonance_tester.py, `VibrationPulseTestGenerator.gen_test`: an
//! acceleration of ±`accel_per_hz`·f flipping sign every half period of f, f rising at
//! `hz_per_sec`) plus its slow ±400 mm/s² square wave of period 1.2 s
//! (`SweepingVibrationsTestGenerator`), held over each sample, through base-excited modes
//! integrated exactly (each mode's relative coordinate x'' + 2ζωx' + ω²x = −a, the 2×2 state
//! transition of a constant input in closed form), the sensor reading a + Σ gᵢ xᵢ'' with
//! participation gᵢ summing to 1, and white noise.

use input_shaping::measure::identify::{identify, Identification, IdentifiedMode, IdentifyOptions};
mod common;
use common::Rng;
use std::f64::consts::PI;

/// A mode of the simulated axis: frequency Hz, damping ratio, peak relative to the others, dB.
struct SimMode {
    f: f64,
    zeta: f64,
    rel_db: f64,
}

fn sim(f: f64, zeta: f64, rel_db: f64) -> SimMode {
    SimMode { f, zeta, rel_db }
}

/// Issue 20's targets for a mode found: 1 % in frequency, 15 % in damping.
fn within(m: &IdentifiedMode, f: f64, zeta: f64) -> bool {
    (m.frequency_hz / f - 1.0).abs() < 0.01 && (m.damping / zeta - 1.0).abs() < 0.15
}

/// Klipper's drive at time t: the sweep's square wave plus the slow square wave, mm/s².
fn drive(t: f64, f0: f64, rate: f64) -> f64 {
    let phase = f0 * t + 0.5 * rate * t * t;
    let f = f0 + rate * t;
    let fast = 60.0 * f * if phase.fract() < 0.5 { 1.0 } else { -1.0 };
    let slow = if (t / 1.2).fract() < 0.5 {
        400.0
    } else {
        -400.0
    };
    fast + slow
}

/// One step h of x'' + 2ζωx' + ω²x = −a with a constant: the exact transition (underdamped).
fn step(state: (f64, f64), a: f64, w: f64, zeta: f64, h: f64) -> (f64, f64) {
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let s = zeta * w;
    // Around the equilibrium x* = −a/ω².
    let xs = -a / (w * w);
    let (x0, v0) = (state.0 - xs, state.1);
    let e = (-s * h).exp();
    let (c, sn) = ((wd * h).cos(), (wd * h).sin());
    let x = e * (x0 * c + (v0 + s * x0) / wd * sn);
    let v = e * (v0 * c - (w * w * x0 + s * v0) / wd * sn);
    (x + xs, v)
}

/// The sensor's record of Klipper's sweep from `f0` to `f1` Hz at `rate` Hz/s, sampled at
/// `fs`, with white noise of `noise` mm/s² (one draw of `seed`).
fn record(
    modes: &[SimMode],
    f0: f64,
    f1: f64,
    rate: f64,
    fs: f64,
    noise: f64,
    seed: u64,
) -> Vec<f64> {
    let duration = (f1 - f0) / rate;
    record_of(modes, duration, fs, noise, seed, |t| drive(t, f0, rate))
}

/// The sensor's record of `duration` s of the drive `a(t)` (mm/s²), sampled at `fs`, with
/// white noise of `noise` mm/s² (one draw of `seed`).
fn record_of(
    modes: &[SimMode],
    duration: f64,
    fs: f64,
    noise: f64,
    seed: u64,
    drive: impl Fn(f64) -> f64,
) -> Vec<f64> {
    // Participation factors in the ratios that put the peaks g/(2ζ) at their relative levels.
    let weights: Vec<f64> = modes
        .iter()
        .map(|m| 2.0 * m.zeta * 10f64.powf(m.rel_db / 20.0))
        .collect();
    let sum: f64 = weights.iter().sum();
    let n = (duration * fs) as usize;
    let h = 1.0 / fs;
    let mut states = vec![(0.0, 0.0); modes.len()];
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ seed);
    (0..n)
        .map(|i| {
            // The drive held over the sample interval ending at this sample (its value at the
            // interval's middle), then the modes advanced over it.
            let a = drive((i as f64 + 0.5) * h);
            let mut y = a;
            for ((m, st), g) in modes.iter().zip(states.iter_mut()).zip(&weights) {
                let w = 2.0 * PI * m.f;
                *st = step(*st, a, w, m.zeta, h);
                let x_dd = -a - 2.0 * m.zeta * w * st.1 - w * w * st.0;
                y += g / sum * x_dd;
            }
            y + noise * rng.normal()
        })
        .collect()
}

/// Exactly `modes` identified, in order, each within issue 20's targets, and no cut-off.
fn all_found(id: &Identification, modes: &[SimMode], label: &str) {
    assert_eq!(id.modes.len(), modes.len(), "{label}: {:?}", id.modes);
    for (m, s) in id.modes.iter().zip(modes) {
        assert!(within(m, s.f, s.zeta), "{} Hz: {m:?}", s.f);
    }
    assert!(id.cut_off.is_none(), "{:?}", id.cut_off);
}

/// Klipper's sweep from `f0` to `f1` Hz at `rate` Hz/s through `modes`, recorded at 3.2 kHz
/// with white noise of `noise` mm/s², one record per seed: each has its sweep found and
/// exactly `modes` identified within the targets ([`all_found`]).
fn all_found_on_draws(modes: &[SimMode], [f0, f1, rate]: [f64; 3], noise: f64, seeds: &[u64]) {
    let fs = 3200.0;
    for &seed in seeds {
        let id = identified(&record(modes, f0, f1, rate, fs, noise, seed), fs);
        assert!(id.sweep.is_some(), "seed {seed}: no sweep");
        all_found(&id, modes, &format!("seed {seed}"));
    }
}

/// The identification of a Klipper raw CSV's `accel_x` with the default options.
fn identified_file(text: &str) -> Identification {
    let options = input_shaping::measure::RecordingOptions::default();
    let Ok(input_shaping::measure::recording::Parsed::Recording(r)) =
        input_shaping::measure::recording::parse_file(text, &options)
    else {
        panic!("not a raw recording");
    };
    identified(&r.channel("accel_x").unwrap().values, r.sample_rate_hz)
}

fn identified(signal: &[f64], fs: f64) -> Identification {
    identify(signal, &IdentifyOptions::new(fs)).unwrap()
}

/// A sharp mode at the very end of a short sweep (59.75 Hz, ζ 0.02, swept 40–60 or 45–60 Hz
/// at 2 Hz/s): it rings all through the test and was the strongest line of every frame, so the
/// sweep went unseen and the Welch path read 56.6 Hz with ζ ≈ 0 and 134 Hz from it. Now: the
/// sweep is found, no mode is reported, and the cut-off is, at the sweep's end.
#[test]
fn a_mode_at_a_raw_sweeps_end_is_reported_cut_off() {
    let fs = 1600.0;
    for (f0, seed) in [(40.0, 1), (45.0, 2), (40.0, 3)] {
        let modes = [sim(59.75, 0.02, 0.0)];
        let id = identified(&record(&modes, f0, 60.0, 2.0, fs, 150.0, seed), fs);
        let sweep = id.sweep.expect("the sweep is found under the ringing mode");
        assert!((sweep.band_hz[1] - 60.0).abs() < 1.0, "{sweep:?}");
        assert!((sweep.rate_hz_per_s - 2.0).abs() < 0.1, "{sweep:?}");
        assert!(id.modes.is_empty(), "from {f0} Hz: {:?}", id.modes);
        let c = id.cut_off.expect("cut off at the sweep's end");
        assert!((c.frequency_hz - sweep.band_hz[1]).abs() < 1e-9, "{c:?}");
        assert!(c.prominence_db >= 6.0, "{c:?}");
        assert_eq!(id.notes.len(), 1);
        assert!(id.notes[0].contains("recording"), "{:?}", id.notes);
    }
}

/// A mode past the end (72 Hz, ζ 0.04, swept 30–70 Hz) beside one inside the band (41 Hz,
/// ζ 0.05, as high): the inside one within issue 20's 1 % / 15 %, the other reported as cut
/// off and not as a mode. And the guard: with a 66 Hz mode the sweep passes (30–80 Hz), both
/// are modes and nothing is cut off.
#[test]
fn a_raw_sweep_cut_off_keeps_the_modes_inside_its_band() {
    let fs = 1600.0;
    for seed in [11, 12] {
        let modes = [sim(41.0, 0.05, 0.0), sim(72.0, 0.04, 0.0)];
        let id = identified(&record(&modes, 30.0, 70.0, 2.0, fs, 150.0, seed), fs);
        assert_eq!(id.modes.len(), 1, "{:?}", id.modes);
        assert!(within(&id.modes[0], 41.0, 0.05), "{:?}", id.modes[0]);
        assert!(id.cut_off.is_some(), "seed {seed}: no cut-off");

        let modes = [sim(41.0, 0.05, 0.0), sim(66.0, 0.04, -3.0)];
        let id = identified(&record(&modes, 30.0, 80.0, 2.0, fs, 150.0, seed), fs);
        assert!(id.cut_off.is_none(), "{:?}", id.cut_off);
        assert!(id.notes.is_empty(), "{:?}", id.notes);
        assert_eq!(id.modes.len(), 2, "{:?}", id.modes);
        for (m, (f, z)) in id.modes.iter().zip([(41.0, 0.05), (66.0, 0.04)]) {
            assert!(within(m, f, z), "{m:?}");
        }
    }
}

/// A broad mode whose high side reaches the end of a short sweep (49.7 Hz, ζ 0.088, swept
/// 34.8–57.1 Hz; 56.8 Hz, ζ 0.06, swept 39.8–62.1 Hz, at 2 Hz/s): its smoothed periodogram
/// falls less than the 6 dB a peak needs inside the fitted band, so no peak was found there
/// and the Welch path read 48.6 Hz with ζ 0.01 and 124.9 Hz from the sweep. Its prominence is
/// now read through the sweep's end, and a peak falling less than 3 dB before the band's top
/// is fitted like a spectrum file's shoulder: each is one mode within 1 % / 15 %.
#[test]
fn a_broad_mode_near_a_raw_sweeps_end_is_found() {
    let fs = 1600.0;
    for (f, zeta, f0, f1, seed) in [
        (49.7, 0.088, 34.8, 57.1, 21),
        (56.8, 0.06, 39.8, 62.1, 22),
        (56.8, 0.06, 39.8, 62.1, 23),
    ] {
        let modes = [sim(f, zeta, 0.0)];
        let id = identified(&record(&modes, f0, f1, 2.0, fs, 250.0, seed), fs);
        assert!(id.sweep.is_some(), "{f} Hz: no sweep");
        assert_eq!(id.modes.len(), 1, "{f} Hz: {:?}", id.modes);
        assert!(within(&id.modes[0], f, zeta), "{:?}", id.modes[0]);
    }
}

/// Short, fast sweeps (1.5–4 s, 22–27 Hz/s: a shaker's chirp or a quick test) with one to
/// three modes inside the band: the record holds fewer than four of the sweep detector's
/// one-second frames, so the sweep went unseen and the Welch path, not meant for sweeps,
/// read each mode 5–10 % low or missed it (benches/reference/sweep_raw_ends.py --short, seed 1:
/// 1 of 37 modes within the targets and 21 spurious). Now the sweep is found on shorter
/// frames, and every mode is within issue 20's 1 % / 15 %, with no other mode. The first
/// machine is issue 20's own example (47.3 Hz, ζ 0.08); the others are a pair at a ratio of
/// 1.6 with the second 3 dB weaker, and three modes 2 and 4 dB apart (the 4 dB case).
#[test]
fn short_fast_sweeps_are_found_and_their_modes_right() {
    let fs = 3200.0;
    let cases: [(&[SimMode], f64, f64, f64, u64); 3] = [
        (&[sim(47.3, 0.08, 0.0)], 30.0, 70.0, 1.5, 31),
        (
            &[sim(36.0, 0.05, 0.0), sim(58.0, 0.04, -3.0)],
            25.0,
            80.0,
            2.5,
            32,
        ),
        (
            &[
                sim(40.0, 0.03, 0.0),
                sim(62.0, 0.06, -2.0),
                sim(95.0, 0.04, -4.0),
            ],
            28.0,
            125.0,
            4.0,
            33,
        ),
    ];
    for (modes, f0, f1, seconds, seed) in cases {
        let rate = (f1 - f0) / seconds;
        let id = identified(&record(modes, f0, f1, rate, fs, 200.0, seed), fs);
        let sweep = id.sweep.expect("the short sweep is found");
        assert!((sweep.rate_hz_per_s / rate - 1.0).abs() < 0.05, "{sweep:?}");
        assert!((sweep.band_hz[0] - f0).abs() < 3.0, "{sweep:?}");
        assert!((sweep.band_hz[1] - f1).abs() < 3.0, "{sweep:?}");
        all_found(&id, modes, &format!("{f0}-{f1} Hz"));
    }
}

/// Exponential (logarithmic) sweeps, as a shaker's sine sweep runs in octaves per minute: f
/// = f₀·e^(βt), so the sweep crawls at its start and races at its end (10 → 250 Hz in 8 s
/// passes 4 Hz/s at 10 Hz and 100 Hz/s at 250 Hz). A sine of constant amplitude and one of
/// amplitude ∝ f (60 mm/s² per Hz, Klipper's) through two or three base-excited modes. The
/// sweep detector fitted only a straight line f(t): it found a sweep over the slow half alone
/// (sweep_chirps.py's seed 1: 5.2–51.1 Hz of a 5–96.5 Hz sweep) or none, and the modes past it
/// were missed or read from the Welch path (of that batch's 48 modes standing ≥ 6 dB, 26
/// within the targets; 44 now). Now ln f(t) is fitted too, the top read again on shorter frames: the law,
/// the band and the rate come back, and every mode is within issue 20's 1 % / 15 %.
#[test]
fn exponential_sweeps_are_found_and_their_modes_right() {
    use input_shaping::measure::SweepLaw;
    let fs = 3200.0;
    // (modes, f₀, f₁, seconds, amplitude ∝ f, noise seed)
    type Case<'a> = (&'a [SimMode], f64, f64, f64, bool, u64);
    let cases: [Case; 4] = [
        (
            &[sim(45.0, 0.03, 0.0), sim(110.0, 0.06, -3.0)],
            10.0,
            250.0,
            8.0,
            true,
            51,
        ),
        (
            &[sim(45.0, 0.03, 0.0), sim(110.0, 0.06, -3.0)],
            10.0,
            250.0,
            8.0,
            false,
            52,
        ),
        (
            &[
                sim(38.0, 0.05, 0.0),
                sim(61.0, 0.02, -4.0),
                sim(140.0, 0.1, -2.0),
            ],
            5.0,
            300.0,
            12.0,
            true,
            53,
        ),
        (&[sim(72.0, 0.015, 0.0)], 20.0, 200.0, 3.0, false, 54),
    ];
    for (modes, f0, f1, seconds, per_hz, seed) in cases {
        let beta = (f1 / f0).ln() / seconds;
        let chirp = |t: f64| {
            let f = f0 * (beta * t).exp();
            let amplitude = if per_hz { 60.0 * f } else { 4000.0 };
            amplitude * (2.0 * PI * f0 * ((beta * t).exp() - 1.0) / beta).sin()
        };
        let id = identified(&record_of(modes, seconds, fs, 150.0, seed, chirp), fs);
        let sweep = id.sweep.expect("the exponential sweep is found");
        assert_eq!(sweep.law, SweepLaw::Exponential, "{sweep:?}");
        assert!((sweep.band_hz[0] / f0 - 1.0).abs() < 0.25, "{sweep:?}");
        assert!((sweep.band_hz[1] / f1 - 1.0).abs() < 0.06, "{sweep:?}");
        let centre = (sweep.band_hz[0] * sweep.band_hz[1]).sqrt();
        assert!(
            (sweep.rate_at(centre) / (beta * centre) - 1.0).abs() < 0.05,
            "{sweep:?}: β {beta}"
        );
        all_found(&id, modes, &format!("{f0}-{f1} Hz"));
    }
}

/// Klipper's own drive made fast (its pulse train swept 5 → 200 and 5 → 133 Hz in 2 s: a quick
/// test in a record of a few seconds) through one low-pass mode (77.7 Hz, ζ 0.095; issue 20's
/// 61 Hz, ζ 0.18), written by benches/reference/sweep_chirps.py (`--fixtures`: 16 times the
/// sensor's rate, drift, the ADXL345's LSB, noise). Near the start the frequency steps by
/// r/(2f) each cycle (9.6 Hz at 5 Hz) and the drive's spectrum is lumpy by ±3–7 dB over a few
/// hertz up to about 4√r; the joint fit's residual search took a lump for a mode (18.97 Hz,
/// ζ 0.0075, standing 4.3 dB; 15.55 Hz, ζ 0.148, standing 7.8 dB). Now a mode found in the
/// residuals must stand 5 dB over the model without it, 8 dB in that rough start: the one
/// mode, within the targets, and nothing else (the second fails with 5 dB in the start).
#[test]
fn a_fast_pulse_sweeps_lumpy_start_makes_no_modes() {
    for (text, f, zeta) in [
        (
            include_str!("data/sweeps/raw_data_x_fastpulses77.csv"),
            77.7,
            0.095,
        ),
        (
            include_str!("data/sweeps/raw_data_x_fastpulses61.csv"),
            61.0,
            0.18,
        ),
    ] {
        let id = identified_file(text);
        assert!(id.sweep.is_some(), "{f} Hz: no sweep");
        assert_eq!(id.modes.len(), 1, "{f} Hz: {:?}", id.modes);
        assert!(within(&id.modes[0], f, zeta), "{:?}", id.modes[0]);
    }
}

/// A flat logarithmic sine sweep (5 → 258 Hz in 6 s at 1 kHz) through three low-pass modes
/// (65.4 Hz ζ 0.116, 113.1 Hz ζ 0.038 at −3.9 dB, 174.9 Hz ζ 0.154 at −3.8 dB: a mass pulled
/// through a spring and damped to the frame, fᵢ²/Dᵢ), written by sweep_chirps.py
/// (`--fixtures`). The joint fit's mode term was only ν²/Dᵢ with a direct term (exact for base
/// excitation and for a force), and read 64.3 / 0.077, 112.1 / 0.041, 159.6 / 0.158. A sweep's
/// modes are now fitted in both forms, the low-pass one kept when its BIC is lower by 10 with
/// no more modes: every mode within issue 20's targets.
#[test]
fn low_pass_modes_under_a_logarithmic_sweep_are_right() {
    let id = identified_file(include_str!("data/sweeps/raw_data_x_logflat3.csv"));
    let sweep = id.sweep.expect("the sweep is found");
    assert_eq!(sweep.law, input_shaping::measure::SweepLaw::Exponential);
    let modes = [
        sim(65.4, 0.1155, 0.0),
        sim(113.1, 0.0376, -3.9),
        sim(174.9, 0.1541, -3.8),
    ];
    all_found(&id, &modes, "logflat3");
}

/// A logarithmic sweep from 5 Hz through one sharp low-pass mode (64.47 Hz, ζ 0.0146), its
/// drive ∝ f under the sensor's noise (σ 268 mm/s²) until it nears the mode (fixture
/// `logunder`, benches/reference/sweep_chirps.py `--fixtures`): the sweep stands over the noise
/// over part of the record only. It is found, a note says it was seen in part, its band holds
/// the mode, and the mode is right with nothing else. Until 2026-12-06 no sweep was found (its
/// line held for under 60 % of the frames) and the Welch path read the same machine at
/// 1.6–3.2 kHz up to 0.8 % high and ζ 17–24 % low (sweep_chirps.py seed 3's c12).
#[test]
fn a_sweep_seen_over_part_of_the_record_is_found_and_its_mode_right() {
    let id = identified_file(include_str!("data/sweeps/raw_data_x_logunder.csv"));
    let sweep = id.sweep.expect("the sweep is found");
    assert!(
        sweep.band_hz[0] < 60.0 && sweep.band_hz[1] > 72.0,
        "{sweep:?}"
    );
    assert!(
        id.notes.iter().any(|n| n.contains("only over")),
        "{:?}",
        id.notes
    );
    all_found(&id, &[sim(64.47, 0.0146, 0.0)], "logunder");
}

/// A logarithmic sweep (23.6 → 118.6 Hz in 15.3 s at 1.6 kHz) through two low-pass modes,
/// 36.6 Hz ζ 0.0143 and 59.4 Hz ζ 0.0139, whose response past the second falls under the
/// sensor's noise (fixture `lognoise84`, sweep_chirps.py seed 8's c16). A bump of noise
/// spikes at 84.2 Hz (half-power ζ 0.042, 9 dB over its surroundings) was fitted as a line,
/// 83.68 Hz ζ 0.00087 ± 0.00065, and reported as a third mode until 2026-12-07: the two modes
/// now, and nothing else.
#[test]
fn a_line_fitted_into_a_sweeps_noise_is_no_mode() {
    let id = identified_file(include_str!("data/sweeps/raw_data_x_lognoise84.csv"));
    assert!(id.sweep.is_some(), "no sweep");
    all_found(
        &id,
        &[sim(36.618, 0.01431, 0.0), sim(59.378, 0.01392, -3.8)],
        "lognoise84",
    );
}

/// A linear sweep, 5 → 197 Hz in 5.1 s at 3.2 kHz, through a base-excited 63.6 Hz, ζ 0.045
/// mode and two weak broad ones, 92.7 / 0.163 and 151.3 / 0.151 (fixture `linhump63`,
/// sweep_chirps.py seed 10's c19). The 62.5 Hz peak (half-power 62.28 Hz, ζ 0.059) was fitted
/// as a hump, 61.48 Hz ζ 0.68, and reported so until 2026-12-07. Such a fit is not the peak's:
/// the peak's own estimate stays, within 3 % and ζ under 0.1. (Not within issue 20's targets:
/// 2.1 % and +33 %, the two weak modes leaning on it.)
#[test]
fn a_hump_far_broader_than_its_peak_is_not_its_fit() {
    let id = identified_file(include_str!("data/sweeps/raw_data_x_linhump63.csv"));
    assert!(id.sweep.is_some(), "no sweep");
    let near: Vec<_> = id
        .modes
        .iter()
        .filter(|m| (m.frequency_hz / 63.63 - 1.0).abs() < 0.05)
        .collect();
    assert_eq!(near.len(), 1, "{:?}", id.modes);
    let m = near[0];
    assert!(
        (m.frequency_hz / 63.63 - 1.0).abs() < 0.03 && m.damping < 0.1,
        "{m:?}"
    );
    assert!(id.modes.iter().all(|m| m.damping < 0.3), "{:?}", id.modes);
}

/// A sweep over a band that holds no mode (one mode at 8 Hz, swept 30–80 Hz at 2 Hz/s):
/// the sweep is reported, no mode, and a note says why. Before, a sweep whose band showed no
/// peak was dropped and the recording went the Welch path, which is not for sweeps, and
/// said nothing.
#[test]
fn a_sweep_over_a_band_without_modes_is_reported_with_a_note() {
    let fs = 1600.0;
    for seed in [41, 42] {
        let modes = [sim(8.0, 0.05, 0.0)];
        let id = identified(&record(&modes, 30.0, 80.0, 2.0, fs, 200.0, seed), fs);
        let sweep = id.sweep.expect("the sweep is reported");
        assert!((sweep.band_hz[0] - 30.0).abs() < 1.0, "{sweep:?}");
        assert!((sweep.band_hz[1] - 80.0).abs() < 1.0, "{sweep:?}");
        assert!(id.modes.is_empty(), "{:?}", id.modes);
        assert_eq!(id.notes.len(), 1, "{:?}", id.notes);
        assert!(id.notes[0].contains("no mode stands out"), "{:?}", id.notes);
        assert!(!id.notes[0].contains("  "), "{:?}", id.notes);
    }
}

/// Random raw sweeps ending around their highest mode, written by
/// benches/reference/sweep_raw_ends.py (`SWEEP_RAW_ENDS_DIR`; docs/measured-data.md). Counts
/// the modes whose high half-power point lies under the sweep's end less √r (inside the
/// fitted band) found within issue 20's 1 % / 15 %, the modes reported that are within 5 % of
/// no true one (spurious), and the recordings with a mode past the end (its frequency over
/// the end) that report it cut off. Prints; fails only on a spurious mode. (Until the sweep
/// detector read short records on shorter frames, a record under 4 s went the Welch path,
/// which is not for sweeps: seed 4's e10, 4.7 s, read three modes there, and `--short`'s
/// records gave 21 spurious modes in 16.) Also reads `--short`'s files.
#[test]
#[ignore = "needs SWEEP_RAW_ENDS_DIR: files generated by benches/reference/sweep_raw_ends.py"]
fn raw_sweep_ends() {
    let Ok(dir) = std::env::var("SWEEP_RAW_ENDS_DIR") else {
        println!("SWEEP_RAW_ENDS_DIR is not set: nothing to do");
        return;
    };
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{dir}/manifest.json")).unwrap())
            .unwrap();
    let (mut inside, mut good, mut spurious, mut past, mut reported) = (0, 0, 0, 0, 0);
    for case in manifest.as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let end = case["end"].as_f64().unwrap();
        let truth: Vec<(f64, f64)> = case["modes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| (m[0].as_f64().unwrap(), m[1].as_f64().unwrap()))
            .collect();
        let text = std::fs::read_to_string(format!("{dir}/raw_data_x_{name}.csv")).unwrap();
        let id = identified_file(&text);
        let mut line = Vec::new();
        for &(f, z) in &truth {
            let ok = id.modes.iter().any(|m| within(m, f, z));
            if f * (1.0 + z) < end - 2f64.sqrt() {
                inside += 1;
                good += usize::from(ok);
                let nearest = id
                    .modes
                    .iter()
                    .min_by(|a, b| {
                        (a.frequency_hz - f)
                            .abs()
                            .total_cmp(&(b.frequency_hz - f).abs())
                    })
                    .map_or("none".into(), |m| {
                        format!(
                            "{:.2} ± {:.2} / {:.4} ± {:.4}",
                            m.frequency_hz,
                            m.frequency_uncertainty_hz,
                            m.damping,
                            m.damping_uncertainty
                        )
                    });
                line.push(format!(
                    "{f:.1}/{z:.3} inside {}",
                    if ok {
                        "ok".into()
                    } else {
                        format!("MISSED (nearest {nearest})")
                    }
                ));
            } else if f > end {
                past += 1;
                reported += usize::from(id.cut_off.is_some());
                line.push(format!("{f:.1}/{z:.3} past"));
            } else {
                line.push(format!("{f:.1}/{z:.3} at the end"));
            }
        }
        let extra: Vec<String> = id
            .modes
            .iter()
            .filter(|m| {
                !truth
                    .iter()
                    .any(|t| (m.frequency_hz / t.0 - 1.0).abs() < 0.05)
            })
            .map(|m| format!("{:.1}/{:.3}", m.frequency_hz, m.damping))
            .collect();
        spurious += extra.len();
        println!(
            "{name} (end {end:.1} Hz, sweep {}): {}; cut off {}{}",
            id.sweep.map_or("NOT found".into(), |s| format!(
                "{:.1}-{:.1} Hz at {:.2} Hz/s",
                s.band_hz[0], s.band_hz[1], s.rate_hz_per_s
            )),
            line.join(", "),
            id.cut_off
                .map_or("no".into(), |c| format!("≥ {:.1} Hz", c.frequency_hz)),
            if extra.is_empty() {
                String::new()
            } else {
                format!("; SPURIOUS {}", extra.join(", "))
            }
        );
    }
    println!(
        "{good} of {inside} modes inside the band within the targets, {spurious} spurious; \
         {reported} of {past} recordings with a mode past the end report it cut off"
    );
    assert_eq!(spurious, 0);
}

/// A short sweep (2 Hz/s, 22.9 → 67 Hz) through three base-excited modes whose peaks stand
/// 7.5, 3.7 and 3.5 dB over their surroundings (`sweep_random.py` seed 13 `--hard`, r36, in
/// this file's own simulation). With the excitation's exponent free, the one-mode fit of the
/// only detected peak bent the excitation instead (E ∝ f^11.9 over the fitted band) and the
/// two-mode fit stood the 30.5 Hz mode 2.3 dB over a model that already explained it by the
/// slope: one mode, 53.6 Hz, came out of every draw. A sweep's fits whose slope a drive has
/// (−6 … 6) are now preferred among the starts': all three modes, within the targets.
#[test]
fn a_sweeps_excitation_slope_does_not_stand_in_for_a_mode() {
    let modes = [
        sim(30.49, 0.085, 0.0),
        sim(40.24, 0.149, -3.76),
        sim(51.51, 0.047, -4.01),
    ];
    all_found_on_draws(&modes, [22.9, 67.0, 2.0], 171.2, &[100, 103, 106]);
}

/// Klipper's whole test (5 → 200 Hz) at 4 Hz/s, recorded raw, through two broad modes a
/// ratio of 1.36 apart (`sweep_random.py --whole-raw` seed 23, f13: 44.36 / 0.119 and 60.35 /
/// 0.113). The pair was fitted as one broad mode and never split in two (or split onto the
/// wrong humps): the humps under it were looked for over the fitted bins, which are thinned
/// away from the seeds (one in 4 in the 49 s record), so the smoothing of ±⌊0.15 ζf/Δf⌋ bins
/// spanned ±7 Hz instead of ±1.8 Hz and flattened the second hump.
/// They are now looked for over every bin of the fitted range. Before: 41.62 / 0.112 and
/// 63.32 / 0.116 from the first draw, 54.82 / 0.333 alone from the second.
#[test]
fn a_broad_pair_under_a_fast_whole_test_sweep_is_split() {
    let modes = [sim(44.36, 0.1188, 0.0), sim(60.35, 0.1129, -0.82)];
    all_found_on_draws(&modes, [5.0, 200.0, 4.0], 150.0, &[200, 201]);
}

/// The same sweep through a broad mode with a sharp, weaker one 1.34 times higher and a third
/// far off (`sweep_random.py --whole-raw` seed 23, f05: 35.87 / 0.142, 48.04 / 0.039, 89.67 /
/// 0.073). The two-mode fit reads the first two as one broad mode; its largest residual lay at
/// 66.7 Hz, and the mode seeded there, accepted first, ended at 49.27 / 0.034 with the broad
/// mode at 34.15 (BIC −4091), while splitting the broad mode on its two humps gives all three
/// (BIC −4314). Both are now tried and the lower BIC kept. Over draws 200–209 of this
/// simulation 8 of 10 meet the targets (4 did before); the other two read the broad mode at
/// 36.42 Hz (1.5 %), the least-squares minimum of those draws.
#[test]
fn a_split_beats_a_residual_mode_that_wandered() {
    let modes = [
        sim(35.87, 0.1416, 0.0),
        sim(48.04, 0.0391, -5.86),
        sim(89.67, 0.073, -0.16),
    ];
    all_found_on_draws(&modes, [5.0, 200.0, 4.0], 150.0, &[200, 202]);
}

/// A fast short sweep (1.4 s at 23 Hz/s, 32.4 → 65.4 Hz) through a mode 9 Hz above its start
/// (41.3 Hz, ζ 0.08; `sweep_chirps.py` seed 5's c19, here through Klipper's drive). The band
/// fitted starts √r = 4.8 Hz above the sweep's start, where the mode's flank stands only
/// ~5 dB under its peak: the peak's prominence was read from there, under 6 dB, and no mode
/// was found. A peak whose low side the band's start cuts is now read on through the start.
#[test]
fn a_mode_near_a_fast_sweeps_start_is_found() {
    all_found_on_draws(
        &[sim(41.3, 0.08, 0.0)],
        [32.4, 65.4, 23.0],
        189.0,
        &[300, 301, 302],
    );
}

/// Klipper's whole test (5–200 Hz) through a sharp mode, a broad one about 6 dB under it and
/// a strong broad one above (`sweep_random.py --whole-raw` seed 58's f07 at 1 Hz/s: 47.35 /
/// 0.021, 81.84 / 0.069, 104.98 / 0.127; seed 53's f34 at 2 Hz/s: 54.69 / 0.016, 73.78 /
/// 0.132, 125.25 / 0.105), here through Klipper's drive. The fit misread the broad ones
/// (f07: 76.3 / 0.20 and 110.5 / 0.114 beside 47.0; f34: one broad mode 53.5 / 0.150 over
/// the lower two, and 128.1 / 0.089). The split on the humps found all three, and was refused
/// twice: its weaker mode stood 3.1–4.8 dB over the model without it, where a sweep's
/// residual modes must stand 5 dB (a split's two modes now need the 3 dB a spectrum's do,
/// `SPECTRUM_STANDING_DB` in identify/model.rs), and f34's broad mode ended at 73.7 Hz,
/// 4.2 Hz from the hump it was seeded on, a quarter of the humps' separation being 3.9 Hz
/// (a mode now stays on its hump within its own half-power half-width too, here 9.7 Hz).
/// Draws 400–405 of each: before, 0 of 12 within the targets; now 12 of 12.
#[test]
fn a_weak_mode_split_off_a_broad_fit_on_a_sweep_is_kept() {
    let f07 = [
        sim(47.35, 0.021, 0.0),
        sim(81.84, 0.0692, -6.27),
        sim(104.98, 0.1269, -0.5),
    ];
    all_found_on_draws(&f07, [5.0, 200.0, 1.0], 182.0, &[400, 401]);
    let f34 = [
        sim(54.69, 0.0163, 0.0),
        sim(73.78, 0.1317, -5.81),
        sim(125.25, 0.1055, -1.26),
    ];
    all_found_on_draws(&f34, [5.0, 200.0, 2.0], 150.0, &[402, 403]);
}
