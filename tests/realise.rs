//! Realisations of designed shapers on each controller (crate::realise), each checked against a
//! closed form or a number the firmware's own source gives (file and function named per test).

mod common;

use common::close;
use input_shaping::realise::{
    realise, ChangeKind, Controller, CurveRange, Realisation, RealiseOptions,
};
use input_shaping::{DesignRequest, Error, ModeSpec, ShaperSpec};
use std::f64::consts::{PI, SQRT_2};

fn request(shaper: ShaperSpec, modes: &[(f64, f64)]) -> DesignRequest {
    DesignRequest {
        modes: modes
            .iter()
            .map(|&(frequency_hz, damping)| ModeSpec {
                frequency_hz,
                damping,
            })
            .collect(),
        shaper,
    }
}

fn on(firmware: Controller, shaper: ShaperSpec, f: f64, zeta: f64) -> Realisation {
    realise(
        &request(shaper, &[(f, zeta)]),
        &RealiseOptions::new(firmware),
    )
    .unwrap()
}

fn amplitudes(r: &Realisation) -> Vec<f64> {
    r.realised.impulses.iter().map(|i| i.amplitude).collect()
}

fn times(r: &Realisation) -> Vec<f64> {
    r.realised.impulses.iter().map(|i| i.time).collect()
}

/// V by its definition (Singhose 2009 eq. 11), written out here independently of the crate:
/// e^{−ζω t_n} |Σ Aᵢ e^{ζω tᵢ} e^{i ω_d tᵢ}| / Σ Aᵢ.
fn v(amplitudes: &[f64], times: &[f64], f: f64, zeta: f64) -> f64 {
    let w = 2.0 * PI * f;
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let tn = times[times.len() - 1];
    let (mut c, mut s) = (0.0, 0.0);
    for (a, t) in amplitudes.iter().zip(times) {
        let g = a * (zeta * w * (t - tn)).exp();
        c += g * (wd * t).cos();
        s += g * (wd * t).sin();
    }
    c.hypot(s) / amplitudes.iter().sum::<f64>()
}

fn field(e: Error) -> String {
    e.field().unwrap_or_default().to_string()
}

#[test]
fn ideal_runs_as_designed() {
    let r = on(Controller::Ideal, ShaperSpec::Zvd, 40.0, 0.1);
    assert!(r.changes.is_empty());
    assert_eq!(r.realised.impulses, r.ideal.impulses);
    assert!(r.summary.starts_with("runs as designed"), "{}", r.summary);
    assert_eq!(r.insensitivity_ideal, r.insensitivity_realised);
}

/// The brief's example: a 60 Hz ZV (ζ = 0) on a 1 ms period. Its half period 8.33 ms rounds to
/// 8 ms, whose zero is at 1/(2 · 8 ms) = 62.5 Hz; at 60 Hz V = |cos(π · 60 · 0.008)|.
#[test]
fn generic_period_moves_the_zero_of_a_zv() {
    let mut options = RealiseOptions::new(Controller::Generic);
    options.period_s = Some(0.001);
    let r = realise(&request(ShaperSpec::Zv, &[(60.0, 0.0)]), &options).unwrap();
    close(times(&r)[1], 0.008, 1e-15, "rounded half period");
    close(r.acts_as_hz.unwrap(), 62.5, 1e-9, "acts as");
    let expected = (PI * 60.0 * 0.008).cos();
    close(r.modes[0].vibration_realised, expected, 1e-12, "V at 60 Hz");
    assert_eq!(
        r.summary,
        "times rounded to 1 ms: the 60 Hz ZV acts as a 62.5 Hz one, V = 6.3 % at the mode"
    );
    assert_eq!(r.changes[0].kind, ChangeKind::Times);
    assert!(r.insensitivity_realised.width < r.insensitivity_ideal.width);
}

/// Undamped ZVD [¼, ½, ¼] on 3 amplitude steps: largest remainders of [0.75, 1.5, 0.75] give
/// [1, 1, 1]/3, whose V at the mode is |1 − 1 + 1|/3 = 1/3.
#[test]
fn generic_amplitude_steps_round_with_the_sum_kept() {
    let mut options = RealiseOptions::new(Controller::Generic);
    options.amplitude_steps = Some(3);
    let r = realise(&request(ShaperSpec::Zvd, &[(10.0, 0.0)]), &options).unwrap();
    for a in amplitudes(&r) {
        close(a, 1.0 / 3.0, 1e-15, "a third");
    }
    close(r.modes[0].vibration_realised, 1.0 / 3.0, 1e-12, "V");
    assert_eq!(r.changes[0].text, "amplitudes rounded to 3 steps");
}

/// ZVD capped at 2 impulses: the first ¼ (smallest, earliest) merges into ½ at T/2, leaving
/// [¾, ¼] half a period apart: V = |¾ − ¼| = ½ undamped.
#[test]
fn generic_cap_merges_the_smallest_impulse() {
    let mut options = RealiseOptions::new(Controller::Generic);
    options.max_impulses = Some(2);
    let r = realise(&request(ShaperSpec::Zvd, &[(10.0, 0.0)]), &options).unwrap();
    close(amplitudes(&r)[0], 0.75, 1e-15, "merged");
    close(amplitudes(&r)[1], 0.25, 1e-15, "kept");
    close(r.modes[0].vibration_realised, 0.5, 1e-12, "V");
    assert_eq!(r.changes[0].kind, ChangeKind::Impulses);
}

#[test]
fn generic_refuses_bad_options_by_field() {
    let req = request(ShaperSpec::Zv, &[(10.0, 0.0)]);
    let mut o = RealiseOptions::new(Controller::Generic);
    o.period_s = Some(-1.0);
    assert_eq!(field(realise(&req, &o).unwrap_err()), "periodS");
    let mut o = RealiseOptions::new(Controller::Generic);
    o.amplitude_steps = Some(0);
    assert_eq!(field(realise(&req, &o).unwrap_err()), "amplitudeSteps");
    let mut o = RealiseOptions::new(Controller::Generic);
    o.max_impulses = Some(0);
    assert_eq!(field(realise(&req, &o).unwrap_err()), "maxImpulses");
    let mut o = RealiseOptions::new(Controller::Generic);
    o.period_s = Some(1e-300);
    assert_eq!(field(realise(&req, &o).unwrap_err()), "periodS");
}

/// Klipper's ZV at 50 Hz, ζ = 0.1 (shaper_defs.py `get_zv_shaper`: A = [1, K],
/// T = [0, ½ t_d], t_d = 1/(f√(1−ζ²))), normalised as kin_shaper.c `init_shaper` does.
#[test]
fn klipper_zv_is_shaper_defs_closed_form() {
    let r = on(Controller::Klipper, ShaperSpec::Zv, 50.0, 0.1);
    let df = (1.0f64 - 0.01).sqrt();
    let k = (-0.1 * PI / df).exp();
    close(amplitudes(&r)[0], 1.0 / (1.0 + k), 1e-15, "A1");
    close(amplitudes(&r)[1], k / (1.0 + k), 1e-15, "A2");
    close(times(&r)[1], 0.5 / (50.0 * df), 1e-15, "T2");
    assert!(r.changes.is_empty(), "{:?}", r.changes);
    assert!(r.modes[0].vibration_realised < 1e-12);
    assert_eq!(r.runs, "zv");
}

/// Klipper's EI at ζ = 0.1 is its fit (shaper_defs.py `get_ei_shaper`), not the exact damped
/// EI: amplitude a1 = (0.24968 + 0.24961 V) + ((0.80008 + 1.23328 V) + (0.49599 + 3.17316 V) ζ) ζ
/// before normalising, with V = 1/20; its times end at t_d.
#[test]
fn klipper_ei_is_the_fitted_one() {
    let r = on(
        Controller::Klipper,
        ShaperSpec::Ei { vtol: 0.05 },
        50.0,
        0.1,
    );
    let vt = 0.05;
    let z = 0.1;
    let a1 =
        (0.24968 + 0.24961 * vt) + ((0.80008 + 1.23328 * vt) + (0.49599 + 3.17316 * vt) * z) * z;
    let a3 =
        (0.25149 + 0.21474 * vt) + ((-0.83249 + 1.41498 * vt) + (0.85181 - 4.90094 * vt) * z) * z;
    let a2 = 1.0 - a1 - a3; // Σ = 1 already
    close(amplitudes(&r)[0], a1, 1e-12, "a1");
    close(amplitudes(&r)[1], a2, 1e-12, "a2");
    close(
        times(&r)[2],
        1.0 / (50.0 * (1.0f64 - 0.01).sqrt()),
        1e-15,
        "t3",
    );
    assert_eq!(r.changes[0].kind, ChangeKind::Family);
    assert!(r.ideal.impulses != r.realised.impulses);
    // The fit puts a hump of about V at the mode, as the exact EI does.
    assert!((r.modes[0].vibration_realised - 0.05).abs() < 0.01);
}

#[test]
fn klipper_refuses_what_it_cannot_run() {
    let req = request(ShaperSpec::Zvdd, &[(50.0, 0.1)]);
    let e = realise(&req, &RealiseOptions::new(Controller::Klipper)).unwrap_err();
    assert_eq!(field(e), "firmware");
    // 2-hump EI beyond Klipper's max_damping_ratio 0.3 (INPUT_SHAPERS).
    let req = request(ShaperSpec::Ei2 { vtol: 0.05 }, &[(50.0, 0.35)]);
    let e = realise(&req, &RealiseOptions::new(Controller::Klipper)).unwrap_err();
    assert_eq!(field(e), "firmware");
}

/// Two modes on Klipper: one frequency per axis, so the second mode is left to ring.
#[test]
fn klipper_shapes_only_the_first_of_several_modes() {
    let req = request(ShaperSpec::Zv, &[(40.0, 0.05), (90.0, 0.05)]);
    let r = realise(&req, &RealiseOptions::new(Controller::Klipper)).unwrap();
    assert_eq!(r.changes[0].kind, ChangeKind::Modes);
    assert!(r.modes[0].vibration_realised < 1e-12);
    assert!(r.modes[1].vibration_realised > 0.1);
    assert!(r.modes[1].vibration_ideal < 1e-9);
}

/// Kalico's K-scaled EI (shaper_defs.py `get_ei_shaper`): amplitudes uᵢKⁱ with the undamped
/// u = [¼(1+V), ½(1−V), ¼(1+V)] at multiples of t_d/2, so e^{ζωtᵢ} = K⁻ⁱ undoes the scaling and
/// V at the mode = K² · |u₁ − u₂ + u₃| / Σ uᵢKⁱ = K² · V / Σ uᵢKⁱ exactly.
#[test]
fn kalico_ei_is_the_k_scaled_form() {
    let zeta = 0.1;
    let r = on(
        Controller::Kalico,
        ShaperSpec::Ei { vtol: 0.05 },
        50.0,
        zeta,
    );
    let k = (-zeta * PI / (1.0 - zeta * zeta).sqrt()).exp();
    let u = [0.2625, 0.475, 0.2625];
    let sum = u[0] + u[1] * k + u[2] * k * k;
    close(
        r.modes[0].vibration_realised,
        k * k * 0.05 / sum,
        1e-12,
        "V at the mode",
    );
    close(amplitudes(&r)[1], u[1] * k / sum, 1e-15, "a2");
    assert_eq!(r.changes[0].kind, ChangeKind::Family);
    // Kalico builds its EI for V = 5 % whatever was designed.
    let r = on(Controller::Kalico, ShaperSpec::Ei { vtol: 0.1 }, 50.0, 0.0);
    close(r.modes[0].vibration_realised, 0.05, 1e-12, "undamped hump");
    assert!(
        r.changes[0].text.contains("built for V = 5 %"),
        "{}",
        r.changes[0].text
    );
}

/// A design Kalico cannot name (two modes) runs as its custom shaper unchanged.
#[test]
fn kalico_runs_other_designs_as_custom() {
    let req = request(ShaperSpec::Zvd, &[(40.0, 0.05), (90.0, 0.05)]);
    let r = realise(&req, &RealiseOptions::new(Controller::Kalico)).unwrap();
    assert_eq!(r.runs, "custom");
    assert_eq!(r.realised.impulses.len(), r.ideal.impulses.len());
    assert!(r.modes.iter().all(|m| m.vibration_realised < 1e-9));
}

/// RRF's ZVD is the exact one (AxisShaper.cpp, case zvd: coefficients 1/(1+K)², …, durations
/// half the damped period): nothing changes.
#[test]
fn rrf_zvd_runs_as_designed() {
    let r = on(Controller::Rrf, ShaperSpec::Zvd, 40.0, 0.1);
    assert!(r.changes.is_empty(), "{:?}", r.changes);
    assert!(r.modes[0].vibration_realised < 1e-12);
    for (a, b) in r.realised.impulses.iter().zip(&r.ideal.impulses) {
        close(a.amplitude, b.amplitude, 1e-12, "amplitude");
        close(a.time, b.time, 1e-15, "time");
    }
}

/// RRF's EI2 (AxisShaper.cpp, case ei2): its durations sum to the cubic 1.49920 − 0.09297ζ −
/// 0.28338ζ² + 1.85710ζ³ times the damped period, where Klipper divides by f alone; its last
/// amplitude is 1 minus the cumulative `coefficients[2]` = (0.16054 + 0.33911 + 0.34089) + ….
#[test]
fn rrf_ei2_scales_the_fit_by_the_damped_period() {
    let (f, z) = (40.0, 0.1);
    let r = on(Controller::Rrf, ShaperSpec::Ei2 { vtol: 0.05 }, f, z);
    let poly = 1.49920 - 0.09297 * z - 0.28338 * z * z + 1.85710 * z * z * z;
    close(
        r.realised.duration,
        poly / (f * (1.0 - z * z).sqrt()),
        1e-15,
        "duration",
    );
    let c2 = (0.16054 + 0.33911 + 0.34089)
        + (0.76699 + 0.45081 - 0.61533) * z
        + (2.26560 - 2.58080 - 0.68765) * z * z
        + (-1.22750 + 1.73650 + 0.42261) * z * z * z;
    close(amplitudes(&r)[3], 1.0 - c2, 1e-12, "last amplitude");
    assert_eq!(r.runs, "ei2");
}

#[test]
fn rrf_runs_zv_as_custom_and_checks_its_range() {
    let r = on(Controller::Rrf, ShaperSpec::Zv, 40.0, 0.1);
    assert_eq!(r.runs, "custom");
    // M593 F below StepClockRate/(2·65535) = 5.72 Hz (AxisShaper::Configure).
    let req = request(ShaperSpec::Zvd, &[(2.0, 0.1)]);
    let e = realise(&req, &RealiseOptions::new(Controller::Rrf)).unwrap_err();
    assert_eq!(field(e), "firmware");
}

/// Marlin classic at 50 Hz, ζ = 0.1 (stepper.cpp `set_shaping_damping_ratio`): factor2 =
/// ⌊64.44056192 − 9.902008832 − 0.0758095488 + 0.043073216⌋ = ⌊54.506⌋ = 54, factor1 = 74; the
/// delay (`set_shaping_frequency`) is (2 MHz / 2)/50 = 20000 ticks = 10 ms, half the undamped
/// period, so the ZV acts at 50/√(1−ζ²) Hz.
#[test]
fn marlin_classic_zv_in_128ths_and_timer_ticks() {
    let r = on(Controller::Marlin, ShaperSpec::Zv, 50.0, 0.1);
    close(amplitudes(&r)[0], 74.0 / 128.0, 0.0, "factor1");
    close(amplitudes(&r)[1], 54.0 / 128.0, 0.0, "factor2");
    close(times(&r)[1], 0.010, 1e-15, "delay");
    close(
        r.acts_as_hz.unwrap(),
        50.0 / (1.0f64 - 0.01).sqrt(),
        1e-9,
        "acts as",
    );
    let expected = v(&[74.0, 54.0], &[0.0, 0.010], 50.0, 0.1);
    close(r.modes[0].vibration_realised, expected, 1e-12, "V");
    // ζ = 0 is special-cased to 64/64.
    let r = on(Controller::Marlin, ShaperSpec::Zv, 50.0, 0.0);
    close(amplitudes(&r)[0], 0.5, 0.0, "half");
    // Anything else becomes Marlin's ZV.
    let r = on(Controller::Marlin, ShaperSpec::Ei { vtol: 0.05 }, 50.0, 0.1);
    assert_eq!(r.changes[0].kind, ChangeKind::Family);
    assert_eq!(r.realised.impulses.len(), 2);
}

/// A slower stepper timer shows the truncation: a 1 kHz tick delays ⌊500/60⌋ = 8 ms at 60 Hz.
#[test]
fn marlin_classic_truncates_the_delay() {
    let mut o = RealiseOptions::new(Controller::Marlin);
    o.period_s = Some(0.001);
    let r = realise(&request(ShaperSpec::Zv, &[(60.0, 0.0)]), &o).unwrap();
    close(times(&r)[1], 0.008, 1e-15, "truncated");
}

/// Marlin FT_MOTION's ZV at 60 Hz (shaping.cpp `set_axis_shaping_N`): Ni[1] = LROUND(0.5/60 ·
/// 1000) = 8 samples of FTM_TS = 1 ms: the same 62.5 Hz zero as the generic 1 ms controller.
#[test]
fn marlin_ft_motion_rounds_to_its_period() {
    let r = on(Controller::MarlinFtMotion, ShaperSpec::Zv, 60.0, 0.0);
    close(times(&r)[1], 0.008, 1e-15, "Ni[1]");
    close(r.acts_as_hz.unwrap(), 62.5, 1e-9, "acts as");
    // ZVD: Ni[2] = 2·Ni[1], so 16 ms, not round(16.67) = 17.
    let r = on(Controller::MarlinFtMotion, ShaperSpec::Zvd, 60.0, 0.0);
    close(times(&r)[2], 0.016, 1e-15, "Ni[2]");
}

/// FT_MOTION's MZV scales by K (the decay over half a damped period) where the impulses are
/// 0.375 t_d apart: with exact times its V at the mode is the closed form of [1, √2K, K²] at
/// 0, 0.375 t_d, 0.75 t_d — not zero when damped, zero undamped.
#[test]
fn marlin_ft_motion_mzv_is_off_the_mode_when_damped() {
    let (f, z) = (40.0, 0.1);
    let mut o = RealiseOptions::new(Controller::MarlinFtMotion);
    o.period_s = Some(1e-10);
    let r = realise(&request(ShaperSpec::Mzv, &[(f, z)]), &o).unwrap();
    let d = (1.0 - z * z).sqrt();
    let k = (-z * PI / d).exp();
    let td = 1.0 / (f * d);
    let expected = v(
        &[1.0, SQRT_2 * k, k * k],
        &[0.0, 0.375 * td, 0.75 * td],
        f,
        z,
    );
    close(r.modes[0].vibration_realised, expected, 1e-6, "V");
    assert!(expected > 0.01, "{expected}");
    let r = realise(&request(ShaperSpec::Mzv, &[(f, 0.0)]), &o).unwrap();
    assert!(r.modes[0].vibration_realised < 1e-6);
}

#[test]
fn marlin_ft_motion_refuses_a_custom_design() {
    let req = request(ShaperSpec::Umzv, &[(40.0, 0.05)]);
    let e = realise(&req, &RealiseOptions::new(Controller::MarlinFtMotion)).unwrap_err();
    assert_eq!(field(e), "firmware");
}

/// Prusa's EI takes `vibration_reduction` (input_shaper.cpp `input_shaper::get`, case ei:
/// v_tol = 1/vibration_reduction): undamped, V at the mode = |¼(1+V) − ½(1−V) + ¼(1+V)| = V.
#[test]
fn prusa_ei_takes_the_designed_tolerance() {
    let r = on(Controller::Prusa, ShaperSpec::Ei { vtol: 0.1 }, 50.0, 0.0);
    close(r.modes[0].vibration_realised, 0.1, 1e-12, "V = vtol");
    let r = on(Controller::Prusa, ShaperSpec::Zv, 50.0, 0.1);
    assert!(r.changes.is_empty());
    let req = request(ShaperSpec::Zvdd, &[(50.0, 0.1)]);
    let e = realise(&req, &RealiseOptions::new(Controller::Prusa)).unwrap_err();
    assert_eq!(field(e), "firmware");
}

/// `curve` asks for both V(f) on one grid; at the mode they are the reported V.
#[test]
fn curves_on_request_agree_with_the_mode_figures() {
    let mut o = RealiseOptions::new(Controller::MarlinFtMotion);
    o.curve = Some(CurveRange {
        from_hz: 0.0,
        to_hz: 120.0,
        points: 121,
    });
    let r = realise(&request(ShaperSpec::Zv, &[(60.0, 0.0)]), &o).unwrap();
    let (a, b) = (
        r.sensitivity_ideal.as_ref().unwrap(),
        r.sensitivity_realised.as_ref().unwrap(),
    );
    close(a.frequency_hz[60], 60.0, 1e-12, "grid");
    close(
        a.vibration[60],
        r.modes[0].vibration_ideal,
        1e-12,
        "ideal at 60 Hz",
    );
    close(
        b.vibration[60],
        r.modes[0].vibration_realised,
        1e-12,
        "realised at 60 Hz",
    );
    o.curve = Some(CurveRange {
        from_hz: 10.0,
        to_hz: 5.0,
        points: 10,
    });
    let e = realise(&request(ShaperSpec::Zv, &[(60.0, 0.0)]), &o).unwrap_err();
    assert!(field(e).starts_with("curve."));
}

/// The realisation chart (crate::chart::realisation) draws the designed curve as one polyline
/// and the realised one dashed (many polylines of a few points) in the same colour, with both in the
/// legend.
#[test]
fn realisation_chart_overlays_designed_and_realised() {
    use input_shaping::chart::{draw_realisation, ChartStyle, SERIES_COLORS};
    use plotters::prelude::*;
    let mut o = RealiseOptions::new(Controller::Generic);
    o.period_s = Some(0.001);
    o.curve = Some(CurveRange {
        from_hz: 0.0,
        to_hz: 150.0,
        points: 300,
    });
    let r = realise(&request(ShaperSpec::Zv, &[(60.0, 0.0)]), &o).unwrap();
    let (a, b) = (
        r.sensitivity_ideal.as_ref().unwrap(),
        r.sensitivity_realised.as_ref().unwrap(),
    );
    let mut out = String::new();
    {
        let area = SVGBackend::with_string(&mut out, (640, 360)).into_drawing_area();
        draw_realisation(
            &area,
            &[("ZV", a, b)],
            Some(0.05),
            &[60.0],
            &ChartStyle::default(),
        )
        .unwrap();
    }
    let c = SERIES_COLORS[0];
    let hex = format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
    let in_colour: Vec<usize> = out
        .split("<polyline")
        .skip(1)
        .filter(|p| p.contains(&hex))
        .map(|p| {
            p.split("points=\"")
                .nth(1)
                .and_then(|r| r.split('"').next())
                .map_or(0, |pts| pts.split(' ').count())
        })
        .collect();
    assert!(
        in_colour.iter().any(|&n| n >= 300),
        "the designed curve whole: {in_colour:?}"
    );
    assert!(
        in_colour.iter().filter(|&&n| n < 10).count() > 20,
        "dashes: {in_colour:?}"
    );
    for want in [
        "ZV",
        "ZV, realised",
        "Vtol 5.000 %",
        "V(f) designed and as run",
    ] {
        assert!(
            out.contains(&format!(">{want}<")) || out.contains(want),
            "{want} missing"
        );
    }
}

/// Klipper's MZV (shaper_defs.py `get_mzv_shaper`, n = 3, t = 0.75) is the crate's `mzv`
/// (crate::design::modified reproduces it): Klipper changes nothing, and V = 0 at the mode.
#[test]
fn klipper_mzv_is_the_crate_mzv() {
    let r = on(Controller::Klipper, ShaperSpec::Mzv, 45.0, 0.1);
    assert!(r.changes.is_empty(), "{:?}", r.changes);
    for (a, b) in r.realised.impulses.iter().zip(&r.ideal.impulses) {
        close(a.amplitude, b.amplitude, 1e-12, "amplitude");
        close(a.time, b.time, 1e-15, "time");
    }
    assert!(r.modes[0].vibration_realised < 1e-9);
}
