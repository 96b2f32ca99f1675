//! Measured data: recordings, Welch PSD, mode identification (issue 7).
//!
//! Synthetic recordings with known modes are generated here independently of the library: a
//! modal sum driven by one white-noise force, discretised exactly (zero-order hold, matrix
//! exponential), or analytic free decays; plus measurement noise, drift and jittered time
//! stamps. The identification must find every mode within 1 % in frequency and 15 % in damping.

use input_shaping::measure::identify::{identify, IdentifyOptions, Method, SignalKind};
use input_shaping::measure::psd::{
    fft_spectrum, welch, Detrend, FftOptions, Scaling, WelchOptions, WindowKind,
};
use input_shaping::measure::recording::{
    parse_recording, write_csv, RecordingFormat, RecordingOptions, RecordingParser,
};
use input_shaping::Error;
use nalgebra::{Matrix2, Vector2};
use std::f64::consts::PI;
use wasm_bindgen_test::wasm_bindgen_test;

mod common;
use common::Rng;

/// Acceleration of Σ modes (f Hz, ζ, gain) driven by one white force held over steps of
/// 1/(4·fs): q'' + 2ζωq' + ω²q = g·u, integrated exactly (matrix exponential), read as an
/// integrate-and-dump accelerometer does: a_k = mean of q'' over [t_k, t_k+1] = (q'(t_k+1) −
/// q'(t_k))·fs — exact, and the same (boxcar) filter on every part of the signal.
fn random_response(modes: &[(f64, f64, f64)], fs: f64, samples: usize, rng: &mut Rng) -> Vec<f64> {
    let dt = 0.25 / fs;
    let systems: Vec<_> = modes
        .iter()
        .map(|&(f, z, g)| {
            let w = 2.0 * PI * f;
            let a = Matrix2::new(0.0, 1.0, -w * w, -2.0 * z * w);
            let phi = (a * dt).exp();
            let gamma =
                a.try_inverse().unwrap() * (phi - Matrix2::identity()) * Vector2::new(0.0, g);
            (phi, gamma)
        })
        .collect();
    let mut states = vec![Vector2::<f64>::zeros(); modes.len()];
    let mut out = Vec::with_capacity(samples);
    for _ in 0..samples {
        let before: f64 = states.iter().map(|s| s[1]).sum();
        for _ in 0..4 {
            let u = rng.normal();
            for (s, (phi, gamma)) in states.iter_mut().zip(&systems) {
                *s = phi * *s + gamma * u;
            }
        }
        let after: f64 = states.iter().map(|s| s[1]).sum();
        out.push((after - before) * fs);
    }
    out
}

fn std_dev(x: &[f64]) -> f64 {
    let m = x.iter().sum::<f64>() / x.len() as f64;
    (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
}

/// Adds white measurement noise (`noise` × the signal's std) and a drift (a line and a
/// 0.05 Hz swing of `drift` × the std).
fn corrupt(x: &mut [f64], fs: f64, noise: f64, drift: f64, rng: &mut Rng) {
    let s = std_dev(x);
    let n = x.len() as f64;
    for (i, v) in x.iter_mut().enumerate() {
        let t = i as f64 / fs;
        *v += noise * s * rng.normal() + drift * s * (i as f64 / n + (2.0 * PI * 0.05 * t).sin());
    }
}

/// Writes samples of `signal(t)` at jittered times (±`jitter` of a step) as CSV text.
fn csv_at_jittered_times(
    fine: &[f64],
    fine_fs: f64,
    fs: f64,
    samples: usize,
    jitter: f64,
    rng: &mut Rng,
) -> String {
    let mut out = String::from("time,accel\n");
    for k in 0..samples {
        let t = (k as f64 + jitter * (2.0 * rng.uniform() - 1.0)) / fs + 1.0 / fs;
        // Cubic (Catmull–Rom) interpolation of the finely sampled signal.
        let x = t * fine_fs;
        let i = x.floor() as usize;
        let s = x - i as f64;
        let p = |j: usize| fine[j.min(fine.len() - 1)];
        let (p0, p1, p2, p3) = (p(i.saturating_sub(1)), p(i), p(i + 1), p(i + 2));
        let v = p1
            + 0.5
                * s
                * (p2 - p0
                    + s * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + s * (3.0 * (p1 - p2) + p3 - p0)));
        out.push_str(&format!("{t:.9},{v:.9e}\n"));
    }
    out
}

fn check_modes(found: &[input_shaping::measure::IdentifiedMode], truth: &[(f64, f64)], what: &str) {
    assert_eq!(
        found.len(),
        truth.len(),
        "{what}: found {:?}",
        found
            .iter()
            .map(|m| (m.frequency_hz, m.damping))
            .collect::<Vec<_>>()
    );
    for (m, &(f, z)) in found.iter().zip(truth) {
        let ef = (m.frequency_hz - f).abs() / f;
        let ez = (m.damping - z).abs() / z;
        eprintln!(
            "{what}: {f} Hz ζ {z}: got {:.4} ± {:.4} Hz, ζ {:.5} ± {:.5} ({:?}); errors {:.3} %, {:.1} %; estimates {:?}",
            m.frequency_hz, m.frequency_uncertainty_hz, m.damping, m.damping_uncertainty, m.method,
            100.0 * ef, 100.0 * ez,
            m.estimates.iter().map(|e| (e.method, e.frequency_hz, e.damping)).collect::<Vec<_>>()
        );
        assert!(ef < 0.01, "{what}: frequency {} vs {f}", m.frequency_hz);
        assert!(ez < 0.15, "{what}: damping {} vs {z}", m.damping);
        assert!(m.frequency_uncertainty_hz > 0.0 && m.damping_uncertainty > 0.0);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn random_excitation_one_mode_with_noise_and_drift() {
    let mut rng = Rng(1);
    let fs = 1000.0;
    let mut x = random_response(&[(42.0, 0.05, 1.0)], fs, 200_000, &mut rng);
    corrupt(&mut x, fs, 0.1, 0.5, &mut rng);
    let id = identify(&x, &IdentifyOptions::new(fs)).unwrap();
    check_modes(&id.modes, &[(42.0, 0.05)], "one mode");
    assert_eq!(id.modes[0].method, Method::SpectrumFit);
    assert!(id.free_decay.is_none());
}

/// Short white-noise records of one broad mode (40 Hz, ζ 0.08, 10 s at 1 kHz, 16 draws):
/// the identified frequency's scatter. A record's information is limited (docs/measured-data.md,
/// *White-noise records*); the fit must not waste it. With the fitted range reaching to three
/// times the mode's frequency (a stationary excitation, `fit_range`) the RMS error is 0.68 %
/// on these draws, against 0.81 % when the range stopped at 1.8 times (the floor, the direct
/// term and the excitation's slope then traded against the frequency).
/// Natively only: 16 records.
#[test]
fn white_noise_records_of_a_broad_mode_scatter_little() {
    let mut rng = Rng(40);
    let fs = 1000.0;
    let mut squares = 0.0;
    let draws = 16;
    for _ in 0..draws {
        let mut x = random_response(&[(40.0, 0.08, 1.0)], fs, 10_000, &mut rng);
        corrupt(&mut x, fs, 0.05, 0.2, &mut rng);
        let id = identify(&x, &IdentifyOptions::new(fs)).unwrap();
        let f = id
            .modes
            .iter()
            .map(|m| m.frequency_hz)
            .min_by(|a, b| (a - 40.0).abs().total_cmp(&(b - 40.0).abs()))
            .unwrap();
        squares += (f / 40.0 - 1.0).powi(2);
    }
    let rms = (squares / draws as f64).sqrt();
    eprintln!(
        "RMS frequency error over {draws} records: {:.3} %",
        100.0 * rms
    );
    assert!(rms < 0.0075, "RMS frequency error {:.3} %", 100.0 * rms);
}

#[wasm_bindgen_test(unsupported = test)]
fn random_excitation_two_modes() {
    let mut rng = Rng(2);
    let fs = 1000.0;
    let mut x = random_response(
        &[(25.0, 0.02, 1.0), (68.0, 0.1, 1.5)],
        fs,
        200_000,
        &mut rng,
    );
    corrupt(&mut x, fs, 0.1, 0.5, &mut rng);
    let id = identify(&x, &IdentifyOptions::new(fs)).unwrap();
    check_modes(&id.modes, &[(25.0, 0.02), (68.0, 0.1)], "two modes");
}

#[wasm_bindgen_test(unsupported = test)]
fn random_excitation_three_modes_uneven_sampling() {
    let mut rng = Rng(3);
    let (fs, fine_fs) = (1000.0, 4000.0);
    let samples = 300_000;
    // A ζ = 0.2 mode stands only 20·log10(1/2ζ) ≈ 8 dB over its own high-frequency asymptote
    // in an acceleration spectrum; the gains (alternating signs, the heavily damped mode
    // strongest) keep it a visible peak.
    let modes = [(18.0, 0.01, 1.0), (47.0, 0.05, -1.0), (110.0, 0.2, 3.0)];
    let mut fine = random_response(&modes, fine_fs, 4 * samples + 16, &mut rng);
    // (4 kHz samples of the process, interpolated at the jittered 1 kHz times below.)
    corrupt(&mut fine, fine_fs, 0.0, 0.5, &mut rng);
    let text = csv_at_jittered_times(&fine, fine_fs, fs, samples, 0.3, &mut rng);
    let rec = parse_recording(&text, &RecordingOptions::default()).unwrap();
    assert!(rec.resampled);
    assert!(
        (rec.sample_rate_hz - fs).abs() < 0.01 * fs,
        "{}",
        rec.sample_rate_hz
    );
    assert!(rec.timing.jitter > 0.05);
    let mut x = rec.channels[0].values.clone();
    corrupt(&mut x, fs, 0.1, 0.0, &mut rng);
    let id = identify(&x, &IdentifyOptions::new(rec.sample_rate_hz)).unwrap();
    check_modes(
        &id.modes,
        &[(18.0, 0.01), (47.0, 0.05), (110.0, 0.2)],
        "three modes, uneven",
    );
}

/// Free decays Σ Aᵢ e^{−σᵢτ} cos(ω_dᵢτ + φᵢ) from `hit` s, quiet before, at times `t`.
fn decay_at(modes: &[(f64, f64, f64, f64)], hit: f64, t: f64) -> f64 {
    if t < hit {
        return 0.0;
    }
    let tau = t - hit;
    modes
        .iter()
        .map(|&(f, z, a, phase)| {
            let w = 2.0 * PI * f;
            a * (-z * w * tau).exp() * ((w * (1.0 - z * z).sqrt()) * tau + phase).cos()
        })
        .sum()
}

#[wasm_bindgen_test(unsupported = test)]
fn free_decay_one_lightly_damped_mode() {
    let mut rng = Rng(4);
    let fs = 1000.0;
    let modes = [(35.0, 0.005, 1.0, 0.3)];
    let mut x: Vec<f64> = (0..20_000)
        .map(|i| decay_at(&modes, 1.0, i as f64 / fs))
        .collect();
    for (i, v) in x.iter_mut().enumerate() {
        *v += 0.02 * rng.normal() + 0.05 * (2.0 * PI * 0.05 * i as f64 / fs).sin() + 0.01;
    }
    let id = identify(&x, &IdentifyOptions::new(fs)).unwrap();
    check_modes(&id.modes, &[(35.0, 0.005)], "decay, one mode");
    assert_eq!(id.modes[0].method, Method::FreeDecay);
    let d = id.free_decay.unwrap();
    assert!((d.start_s - 1.0).abs() < 0.1, "{d:?}");
}

/// A short record that is mostly ring-down (issue 20's slow-mode case for a hit): 12 Hz,
/// ζ 0.02, 3 s at 1 kHz, hit at 0.5 s. The decay lasts most of the record (time constant
/// 0.66 s), so the median block is part of it; Welch bins of 1.95 Hz are wider than the
/// mode (0.48 Hz): the damping must come from the ring-down, not a half-power width.
#[wasm_bindgen_test(unsupported = test)]
fn free_decay_short_record_mostly_ringing() {
    let mut rng = Rng(6);
    let fs = 1000.0;
    let modes = [(12.0, 0.02, 1.0, 0.4)];
    let mut x: Vec<f64> = (0..3000)
        .map(|i| decay_at(&modes, 0.5, i as f64 / fs))
        .collect();
    for (i, v) in x.iter_mut().enumerate() {
        *v += 0.01 * rng.normal() + 0.02 * i as f64 / 3000.0 + 0.01;
    }
    let id = identify(&x, &IdentifyOptions::new(fs)).unwrap();
    check_modes(&id.modes, &[(12.0, 0.02)], "short decay");
    assert_eq!(id.modes[0].method, Method::FreeDecay);
}

#[wasm_bindgen_test(unsupported = test)]
fn free_decay_three_modes_uneven_sampling_and_drift() {
    let mut rng = Rng(5);
    let fs = 1000.0;
    let modes = [
        (12.0, 0.005, 1.0, 0.0),
        (31.0, 0.03, 0.8, 1.0),
        (77.0, 0.08, 2.0, 2.0),
    ];
    let mut text = String::from("# tap test\ntime;accel\n");
    for k in 0..30_000 {
        let t = (k as f64 + 0.3 * (2.0 * rng.uniform() - 1.0)) / fs;
        let v = decay_at(&modes, 2.0, t) + 0.02 * rng.normal() + 0.1 * t / 30.0;
        text.push_str(&format!("{t:.7};{v:.7}\n"));
    }
    let rec = parse_recording(&text, &RecordingOptions::default()).unwrap();
    assert!(rec.resampled);
    let id = identify(
        &rec.channels[0].values,
        &IdentifyOptions::new(rec.sample_rate_hz),
    )
    .unwrap();
    check_modes(
        &id.modes,
        &[(12.0, 0.005), (31.0, 0.03), (77.0, 0.08)],
        "decay, three modes",
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn velocity_and_position_signals_use_their_peak_relation() {
    // A heavily damped mode seen in position: its PSD peaks at fₙ√(1−2ζ²), 4 % low at ζ = 0.2.
    let mut rng = Rng(6);
    let fs = 1000.0;
    let acc = random_response(&[(60.0, 0.2, 1.0)], fs, 200_000, &mut rng);
    // Position by double integration in the frequency domain would need the library's FFT; a
    // position signal is instead produced by the modal state itself.
    let w = 2.0 * PI * 60.0;
    let a = Matrix2::new(0.0, 1.0, -w * w, -0.4 * w);
    let phi = (a / fs).exp();
    let gamma = a.try_inverse().unwrap() * (phi - Matrix2::identity()) * Vector2::new(0.0, 1.0);
    let mut s = Vector2::zeros();
    let mut rng = Rng(7);
    let mut pos: Vec<f64> = (0..200_000)
        .map(|_| {
            let u = rng.normal();
            let q = s[0];
            s = phi * s + gamma * u;
            q
        })
        .collect();
    corrupt(&mut pos, fs, 0.05, 0.0, &mut rng);
    let id = identify(
        &pos,
        &IdentifyOptions {
            signal: SignalKind::Position,
            ..IdentifyOptions::new(fs)
        },
    )
    .unwrap();
    check_modes(&id.modes, &[(60.0, 0.2)], "position, ζ = 0.2");
    let _ = acc;
}

// ---- Welch PSD against independent computations ----------------------------------------

/// The signal of benches/reference/welch_reference.py.
fn reference_signal() -> Vec<f64> {
    (0..1000)
        .map(|i| {
            let n = i as f64;
            (2.0 * PI * 0.1 * n).sin()
                + 0.5 * (2.0 * PI * 0.237 * n + 0.3).cos()
                + 0.01 * n
                + 0.2 * ((i * 7919) % 13) as f64 / 13.0
        })
        .collect()
}

// Generated by benches/reference/welch_reference.py (scipy 1.17.1, numpy 2.4).
// hann_128_64_constant: len 65
const HANN_128_64_CONSTANT: &[(usize, f64)] = &[
    (0, 0.00013184662517768322),
    (1, 0.039904366704993144),
    (5, 5.0643723889218534e-06),
    (10, 0.00013754405324495198),
    (13, 0.4051704333885685),
    (24, 1.6177880478337163e-07),
    (30, 0.0926103789072916),
    (50, 6.735282334255051e-05),
];
// hamming_200_50_linear: len 101
const HAMMING_200_50_LINEAR: &[(usize, f64)] = &[
    (0, 2.583155456327199e-06),
    (1, 0.0003777449417521154),
    (5, 4.6131733937385227e-07),
    (10, 2.7798495171943984e-07),
    (13, 3.5000189134576167e-07),
    (24, 6.20602073755555e-07),
    (30, 0.001136932423269214),
    (50, 1.7838798324240504e-07),
];
// kaiser6_sym_256_128_constant: len 129
const KAISER6_SYM_256_128_CONSTANT: &[(usize, f64)] = &[
    (0, 0.00014449632964494617),
    (1, 0.32285037002973654),
    (5, 4.2987571072951475e-06),
    (10, 3.8805679600178635e-06),
    (13, 2.867306686209937e-06),
    (24, 0.013052214758138845),
    (30, 6.92384612252175e-07),
    (50, 4.210588342086706e-07),
];
// boxcar_100_0_none_spectrum: len 51
const BOXCAR_100_0_NONE_SPECTRUM: &[(usize, f64)] = &[
    (0, 34.1281910759221),
    (1, 0.05070770718885995),
    (5, 0.002072530623119364),
    (10, 0.4700138530849462),
    (13, 0.0004432817101188844),
    (24, 0.09218945965271227),
    (30, 0.0003946805717596531),
    (50, 3.9301020668677695e-05),
];

fn assert_reference(options: WelchOptions, reference: &[(usize, f64)], bins: usize, what: &str) {
    let psd = welch(&reference_signal(), &options).unwrap();
    assert_eq!(psd.psd.len(), bins, "{what}");
    for &(k, want) in reference {
        let got = psd.psd[k];
        assert!(
            (got - want).abs() <= 1e-9 * want.abs() + 1e-15,
            "{what} bin {k}: {got} vs scipy {want}"
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn welch_matches_scipy() {
    let base = WelchOptions::new(100.0);
    assert_reference(
        WelchOptions {
            segment_length: Some(128),
            overlap: Some(64),
            ..base.clone()
        },
        HANN_128_64_CONSTANT,
        65,
        "hann",
    );
    assert_reference(
        WelchOptions {
            segment_length: Some(200),
            overlap: Some(50),
            window: WindowKind::Hamming,
            detrend: Detrend::Linear,
            ..base.clone()
        },
        HAMMING_200_50_LINEAR,
        101,
        "hamming, linear detrend",
    );
    assert_reference(
        WelchOptions {
            segment_length: Some(256),
            overlap: Some(128),
            window: WindowKind::Kaiser,
            kaiser_beta: 6.0,
            symmetric_window: true,
            ..base.clone()
        },
        KAISER6_SYM_256_128_CONSTANT,
        129,
        "kaiser (Klipper's window)",
    );
    assert_reference(
        WelchOptions {
            segment_length: Some(100),
            overlap: Some(0),
            window: WindowKind::Rectangular,
            detrend: Detrend::None,
            scaling: Scaling::Spectrum,
            ..base
        },
        BOXCAR_100_0_NONE_SPECTRUM,
        51,
        "boxcar, spectrum scaling",
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn welch_parseval_with_a_rectangular_window() {
    // Rectangular window, no overlap, no detrend: Σ P Δf = mean square of the signal exactly.
    let mut rng = Rng(9);
    let x: Vec<f64> = (0..4096).map(|_| rng.normal() * 3.0 + 0.5).collect();
    let psd = welch(
        &x,
        &WelchOptions {
            segment_length: Some(512),
            overlap: Some(0),
            window: WindowKind::Rectangular,
            detrend: Detrend::None,
            ..WelchOptions::new(250.0)
        },
    )
    .unwrap();
    let power: f64 = psd.psd.iter().sum::<f64>() * psd.resolution_hz;
    let mean_square = x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64;
    assert!(
        (power - mean_square).abs() < 1e-10 * mean_square,
        "{power} vs {mean_square}"
    );
    assert_eq!(psd.segments, 8);
}

#[wasm_bindgen_test(unsupported = test)]
fn welch_white_noise_level_and_sinusoid_power() {
    // White noise of variance σ² sampled at f_s has a one-sided density 2σ²/f_s.
    let mut rng = Rng(10);
    let fs = 200.0;
    let x: Vec<f64> = (0..200_000).map(|_| 2.0 * rng.normal()).collect();
    let psd = welch(&x, &WelchOptions::new(fs)).unwrap();
    let mid = &psd.psd[5..120];
    let mean = mid.iter().sum::<f64>() / mid.len() as f64;
    assert!((mean - 2.0 * 4.0 / fs).abs() < 0.01 * 8.0 / fs, "{mean}");
    // A sinusoid of amplitude A on a bin: the power spectrum reads A²/2 there (Hann).
    let a = 3.0;
    let f0 = 25.0 * fs / 256.0;
    let y: Vec<f64> = (0..25_600)
        .map(|i| a * (2.0 * PI * f0 * i as f64 / fs + 0.4).sin())
        .collect();
    let ps = welch(
        &y,
        &WelchOptions {
            scaling: Scaling::Spectrum,
            ..WelchOptions::new(fs)
        },
    )
    .unwrap();
    assert!((ps.psd[25] - a * a / 2.0).abs() < 1e-9, "{}", ps.psd[25]);
    assert!((ps.enbw_bins - 1.5).abs() < 1e-12);
}

#[wasm_bindgen_test(unsupported = test)]
fn klipper_welch_settings() {
    let o = WelchOptions::klipper(3200.0);
    // 1 << int(3200·0.5 − 1).bit_length() = 1 << 11
    assert_eq!(o.segment_length, Some(2048));
    assert_eq!(o.overlap, Some(1024));
    assert_eq!(o.window, WindowKind::Kaiser);
    assert!(o.symmetric_window);
}

#[wasm_bindgen_test(unsupported = test)]
fn fft_amplitude_spectrum_of_any_length() {
    // 1000 samples (Bluestein): a 2-amplitude sinusoid on bin 37 reads 2 there, others ~0.
    let fs = 500.0;
    let n = 1000;
    let f0 = 37.0 * fs / n as f64;
    let x: Vec<f64> = (0..n)
        .map(|i| 2.0 * (2.0 * PI * f0 * i as f64 / fs).cos() + 1.0)
        .collect();
    let s = fft_spectrum(
        &x,
        &FftOptions {
            sample_rate_hz: fs,
            ..FftOptions::default()
        },
    )
    .unwrap();
    assert_eq!(s.magnitude.len(), 501);
    assert!((s.magnitude[37] - 2.0).abs() < 1e-9);
    assert!(s.magnitude[0] < 1e-9, "constant detrend removes the offset");
    assert!(s
        .magnitude
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != 37)
        .all(|(_, m)| *m < 1e-9));
}

// ---- Recordings ---------------------------------------------------------------------------

fn klipper_text(rows: usize, fs: f64) -> String {
    let mut out = String::from("#time,accel_x,accel_y,accel_z\n");
    for k in 0..rows {
        let t = 100.0 + k as f64 / fs;
        out.push_str(&format!(
            "{t:.6},{:.6},{:.6},{:.6}\n",
            1000.0 * (2.0 * PI * 40.0 * t).sin(),
            -250.5 + k as f64 * 0.001,
            9810.0
        ));
    }
    out
}

#[wasm_bindgen_test(unsupported = test)]
fn klipper_file_round_trips() {
    let text = klipper_text(3200, 3200.0);
    let rec = parse_recording(&text, &RecordingOptions::default()).unwrap();
    assert_eq!(rec.format, RecordingFormat::Klipper);
    assert_eq!(rec.rows, 3200);
    assert_eq!(
        rec.channels
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>(),
        ["accel_x", "accel_y", "accel_z"]
    );
    assert!(
        (rec.sample_rate_hz - 3200.0).abs() < 1e-6 * 3200.0,
        "{}",
        rec.sample_rate_hz
    );
    assert!(
        !rec.resampled,
        "6-decimal rounding of the times is not jitter"
    );
    let written = write_csv(&rec);
    assert_eq!(written, text, "write(parse(file)) is the file");
    let again = parse_recording(&written, &RecordingOptions::default()).unwrap();
    assert_eq!(again, rec);
}

#[wasm_bindgen_test(unsupported = test)]
fn chunked_parsing_equals_whole_parsing() {
    let text = klipper_text(500, 1000.0);
    let whole = parse_recording(&text, &RecordingOptions::default()).unwrap();
    for chunk in [1usize, 7, 64, 1000] {
        let mut p = RecordingParser::new(RecordingOptions::default());
        let bytes = text.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            let j = (i + chunk).min(bytes.len());
            p.push(std::str::from_utf8(&bytes[i..j]).unwrap()).unwrap();
            i = j;
        }
        assert_eq!(p.finish().unwrap(), whole, "chunks of {chunk}");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn generic_csv_with_named_time_column_and_milliseconds() {
    let text = "Stamp (ms)\tx\ty\r\n0\t1\t2\r\n2\t3\t4\r\n4\t5\t6\r\n";
    let rec = parse_recording(
        text,
        &RecordingOptions {
            time_column: Some("stamp (ms)".into()),
            time_scale: 1e-3,
            ..RecordingOptions::default()
        },
    )
    .unwrap();
    assert_eq!(rec.format, RecordingFormat::Csv);
    assert!((rec.sample_rate_hz - 500.0).abs() < 1e-9);
    assert_eq!(rec.channels[1].values, vec![2.0, 4.0, 6.0]);
}

#[wasm_bindgen_test(unsupported = test)]
fn resampling_an_uneven_recording_keeps_a_smooth_signal() {
    let mut text = String::from("t,v\n");
    let mut rng = Rng(11);
    let f = 1.0;
    for k in 0..2000 {
        let t = (k as f64 + 0.4 * (rng.uniform() - 0.5)) / 100.0;
        text.push_str(&format!("{t},{}\n", (2.0 * PI * f * t).sin()));
    }
    let rec = parse_recording(&text, &RecordingOptions::default()).unwrap();
    assert!(rec.resampled);
    let time = rec.time();
    // Inside (the two end intervals use one-sided slopes).
    let worst = rec.channels[0].values[2..1998]
        .iter()
        .zip(&time[2..1998])
        .map(|(v, t)| (v - (2.0 * PI * f * t).sin()).abs())
        .fold(0.0, f64::max);
    // Linear interpolation would err by up to (2πf·h)²/8 ≈ 5·10⁻⁴ here.
    assert!(worst < 1e-4, "cubic interpolation error {worst}");
}

fn parse_error(text: &str) -> input_shaping::measure::recording::RecordingError {
    parse_recording(text, &RecordingOptions::default()).unwrap_err()
}

#[wasm_bindgen_test(unsupported = test)]
fn bad_files_name_the_line_and_column() {
    let e = parse_error("");
    assert!(e.reason.contains("empty"), "{e}");
    let e = parse_error("#time,accel_x\n0,1\n0.001,abc\n");
    assert_eq!((e.line, e.column), (3, Some(2)), "{e}");
    assert_eq!(
        e.to_string(),
        "line 3, column 2 (`accel_x`): `abc` is not a number"
    );
    let e = parse_error("time,a\n0,1\n0.1,NaN\n");
    assert_eq!((e.line, e.column), (3, Some(2)), "{e}");
    assert!(e.reason.contains("finite"));
    let e = parse_error("foo,bar\n1,2\n");
    assert_eq!((e.line, e.column), (1, None));
    assert!(e.reason.contains("no time column"), "{e}");
    let e = parse_error("0,1\n1,2\n");
    assert!(e.reason.contains("no header"), "{e}");
    let e = parse_error("time,a\n0,1\n");
    assert!(e.reason.contains("1 data row"), "{e}");
    let e = parse_error("time,a\n0,1\n1,2,3\n");
    assert_eq!(e.line, 3);
    assert!(e.reason.contains("3 values"), "{e}");
    let e = parse_error("time,a\n0,1\n0,2\n");
    assert_eq!((e.line, e.column), (3, Some(1)));
    assert!(e.reason.contains("does not increase"), "{e}");
    let e = parse_error("time,a\n0,1\n1,\n");
    assert_eq!((e.line, e.column), (3, Some(2)));
    let e = parse_error("time\n0\n1\n");
    assert!(e.reason.contains("signal column"), "{e}");
    let long = format!("time,a\n0,{}\n", "1".repeat(70_000));
    let e = parse_error(&long);
    assert!(matches!(Error::from(e), Error::TooLarge { .. }));
    let e: Error = parse_error("time,a\n0,x\n").into();
    assert!(
        matches!(&e, Error::Parse { field, .. } if field == "recording"),
        "{e}"
    );
    assert!(e.to_string().contains("line 2, column 2"), "{e}");
}

#[wasm_bindgen_test(unsupported = test)]
fn bad_spectrum_and_identification_inputs_are_typed_errors() {
    let x = vec![0.0; 1000];
    let field = |e: Error| e.field().unwrap_or("").to_string();
    assert_eq!(
        field(welch(&x, &WelchOptions::new(f64::NAN)).unwrap_err()),
        "sampleRateHz"
    );
    assert_eq!(
        field(welch(&x, &WelchOptions::new(-1.0)).unwrap_err()),
        "sampleRateHz"
    );
    assert_eq!(
        field(welch(&[1.0], &WelchOptions::new(1.0)).unwrap_err()),
        "signal"
    );
    let mut y = x.clone();
    y[17] = f64::INFINITY;
    assert_eq!(
        field(welch(&y, &WelchOptions::new(1.0)).unwrap_err()),
        "signal[17]"
    );
    let o = WelchOptions {
        segment_length: Some(64),
        overlap: Some(64),
        ..WelchOptions::new(1.0)
    };
    assert_eq!(field(welch(&x, &o).unwrap_err()), "overlap");
    let o = WelchOptions {
        segment_length: Some(1 << 30),
        ..WelchOptions::new(1.0)
    };
    assert!(matches!(welch(&x, &o).unwrap_err(), Error::TooLarge { .. }));
    assert_eq!(
        field(identify(&x[..10], &IdentifyOptions::new(1.0)).unwrap_err()),
        "signal"
    );
    let o = IdentifyOptions {
        max_modes: 0,
        ..IdentifyOptions::new(100.0)
    };
    assert_eq!(field(identify(&x, &o).unwrap_err()), "maxModes");
    let o = IdentifyOptions {
        max_frequency_hz: Some(80.0),
        ..IdentifyOptions::new(100.0)
    };
    assert_eq!(field(identify(&x, &o).unwrap_err()), "maxFrequencyHz");
    // Silence: no peaks, no error.
    assert!(identify(&x, &IdentifyOptions::new(100.0))
        .unwrap()
        .modes
        .is_empty());
}
