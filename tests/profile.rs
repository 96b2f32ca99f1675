//! Pulse-convolution profiles (Veciana & Cardona 2011): distance and duration met, spectral
//! zeros at the modes (eqs. 13, 23, Fig. 8, §2.4), the B-spline form (eqs. 29–30), no residual
//! vibration on undamped modes, and the damped-system claims of §3.3.

mod common;

use common::close;
use input_shaping::metrics::mode_residual_percent;
use input_shaping::plant::ModalPlant;
use input_shaping::profile::{
    from_spec, position_from_pulses, spectrum_zeros, to_bspline, ProfileSpec, SpectrumZero,
};
use input_shaping::spectrum::{piecewise_spectrum, SpectrumOptions, SpectrumSignal};
use input_shaping::{Error, Mode};
use std::f64::consts::PI;
use wasm_bindgen_test::wasm_bindgen_test;

fn velocity_spectrum_at(p: &input_shaping::command::Piecewise, f: f64) -> f64 {
    piecewise_spectrum(
        p,
        &SpectrumOptions {
            from_hz: f,
            to_hz: f + 1e-9,
            points: 2,
            signal: SpectrumSignal::Velocity,
        },
    )
    .unwrap()
    .magnitude[0]
}

fn residual(z: f64, p: &input_shaping::command::Piecewise) -> f64 {
    let plant = ModalPlant::new(vec![Mode::new(1.0, z).unwrap()], vec![1.0]).unwrap();
    mode_residual_percent(&plant, p).unwrap().unwrap()[0]
}

/// Every profile covers `distance` in exactly `duration` and starts and ends at rest.
#[wasm_bindgen_test(unsupported = test)]
fn profiles_meet_distance_and_duration() {
    let specs = [
        ProfileSpec::Pulse {
            frequency_hz: 2.0,
            distance: 0.7,
            duration: 1.3,
        },
        ProfileSpec::Triangle {
            frequency_hz: 2.0,
            distance: -1.5,
            duration: 2.0,
        },
        ProfileSpec::RobustTrapezium {
            frequency_hz: 2.0,
            delta_hz: 0.3,
            distance: 3.0,
            duration: 2.5,
        },
        ProfileSpec::MultiMode {
            modes_hz: vec![1.2, 3.4],
            common_hz: None,
            distance: 680.0,
            duration: 1.9,
        },
    ];
    for spec in &specs {
        let p = from_spec(spec).unwrap();
        let (d, t) = match spec {
            ProfileSpec::Pulse {
                distance, duration, ..
            }
            | ProfileSpec::Triangle {
                distance, duration, ..
            }
            | ProfileSpec::RobustTrapezium {
                distance, duration, ..
            }
            | ProfileSpec::MultiMode {
                distance, duration, ..
            } => (*distance, *duration),
        };
        close(p.start_time(), 0.0, 0.0, "starts at 0");
        close(p.end_time(), t, 1e-12, "duration");
        let end = p.final_state();
        close(end[0], d, 1e-9 * d.abs(), "distance");
        for (k, v) in end.iter().enumerate().skip(1) {
            assert!(
                v.abs() < 1e-9 * d.abs().max(1.0),
                "derivative {k} at the end: {v}"
            );
        }
        assert!(p.ends_at_rest());
    }
}

/// Eq. 13 and the convolution theorem: the pulse profile's velocity spectrum is
/// D |sin(πf/f₀)/(πf/f₀)| |sin(πf t₂)/(πf t₂)|, zero at f₀, 2f₀, …; eq. 23 (p = 1): the triangle
/// makes the spectrum tangent to zero at f₀; Fig. 8: the robust trapezium has zeros at f₀ ± Δf.
#[wasm_bindgen_test(unsupported = test)]
fn spectral_zeros_at_the_modes() {
    let (f0, d, tf) = (1.5, 2.0, 2.2);
    let pulse = from_spec(&ProfileSpec::Pulse {
        frequency_hz: f0,
        distance: d,
        duration: tf,
    })
    .unwrap();
    let t2 = tf - 1.0 / f0;
    let sinc = |x: f64| if x == 0.0 { 1.0 } else { x.sin() / x };
    for &f in &[0.05, 0.3, 0.77, 1.1, 2.9, 4.2, 9.7] {
        let want = d * (sinc(PI * f / f0) * sinc(PI * f * t2)).abs();
        close(
            velocity_spectrum_at(&pulse, f),
            want,
            1e-9,
            "eq. 13 × final pulse",
        );
    }
    for k in 1..=3 {
        assert!(velocity_spectrum_at(&pulse, k as f64 * f0) < 1e-9);
    }
    let tri = from_spec(&ProfileSpec::Triangle {
        frequency_hz: f0,
        distance: d,
        duration: 3.0,
    })
    .unwrap();
    let h = 1e-4;
    // Tangent zero: |U| = O((f − f₀)²).
    assert!(velocity_spectrum_at(&tri, f0) < 1e-9);
    let side = velocity_spectrum_at(&tri, f0 + h) + velocity_spectrum_at(&tri, f0 - h);
    assert!(side < 1e-5, "triangle spectrum near f0: {side}");
    let side_pulse = velocity_spectrum_at(&pulse, f0 + h);
    assert!(
        side_pulse > 1e-5,
        "pulse spectrum is not tangent: {side_pulse}"
    );
    let robust = from_spec(&ProfileSpec::RobustTrapezium {
        frequency_hz: f0,
        delta_hz: 0.2,
        distance: d,
        duration: 3.0,
    })
    .unwrap();
    assert!(velocity_spectrum_at(&robust, f0 + 0.2) < 1e-9);
    assert!(velocity_spectrum_at(&robust, f0 - 0.2) < 1e-9);
}

/// §2.4 and eq. 28: one pulse per mode puts a zero at each; a common frequency f_cmd with
/// fᵢ ≈ integer × f_cmd puts zeros at all its multiples with one pulse.
#[wasm_bindgen_test(unsupported = test)]
fn multi_mode_and_common_frequency() {
    let modes = vec![1.2, 3.4, 5.3];
    let p = from_spec(&ProfileSpec::MultiMode {
        modes_hz: modes.clone(),
        common_hz: None,
        distance: 1.0,
        duration: 2.0,
    })
    .unwrap();
    for &f in &modes {
        assert!(velocity_spectrum_at(&p, f) < 1e-9, "zero at {f} Hz");
    }
    // f_cmd = 1 Hz covers 2, 3 and 5 Hz with one 1 s pulse (shorter than 1/2 + 1/3 + 1/5 s).
    let c = from_spec(&ProfileSpec::MultiMode {
        modes_hz: vec![],
        common_hz: Some(1.0),
        distance: 1.0,
        duration: 1.5,
    })
    .unwrap();
    for f in [2.0, 3.0, 5.0] {
        assert!(velocity_spectrum_at(&c, f) < 1e-9);
    }
    assert!(matches!(
        from_spec(&ProfileSpec::MultiMode {
            modes_hz: vec![],
            common_hz: None,
            distance: 1.0,
            duration: 1.5,
        })
        .unwrap_err(),
        Error::InvalidInput { .. }
    ));
}

/// Eqs. 29–30: the triangle-convolved-with-a-pulse velocity (Fig. 11) is the quadratic
/// B-spline with (Farin) knots {0, 0, 1/f₀, 2/f₀, t_f − 2/f₀, t_f − 1/f₀, t_f, t_f} and control
/// ordinates {0, 0, A, A, A, 0, 0}, A the plateau velocity D/(t_f − 2/f₀).
#[wasm_bindgen_test(unsupported = test)]
fn bspline_form_matches_eqs_29_30() {
    let (f0, d, tf) = (1.25, 3.0, 4.1);
    let p = from_spec(&ProfileSpec::Triangle {
        frequency_hz: f0,
        distance: d,
        duration: tf,
    })
    .unwrap();
    let v = p.derivative().unwrap();
    let b = to_bspline(&v).unwrap();
    assert_eq!(b.degree, 2);
    let a = 1.0 / f0;
    let want_knots = [0.0, 0.0, a, 2.0 * a, tf - 2.0 * a, tf - a, tf, tf];
    let got = b.farin_knots();
    assert_eq!(got.len(), want_knots.len());
    for (g, w) in got.iter().zip(want_knots) {
        close(*g, w, 1e-12, "knot (eq. 29)");
    }
    let plateau = d / (tf - 2.0 * a);
    let want_ctrl = [0.0, 0.0, plateau, plateau, plateau, 0.0, 0.0];
    assert_eq!(b.control.len(), 7);
    for (g, w) in b.control.iter().zip(want_ctrl) {
        close(*g, w, 1e-10, "control ordinate (eq. 30)");
    }
    // De Boor evaluation reproduces the profile (and so does any other profile).
    let other = position_from_pulses(&[0.3, 0.45, 0.2, 1.1], 2.0)
        .unwrap()
        .derivative()
        .unwrap();
    let bo = to_bspline(&other).unwrap();
    assert_eq!(bo.degree, 3);
    for i in 0..=500 {
        let t = i as f64 * tf / 500.0;
        close(b.eval(t), v.eval(t)[0], 1e-10, "B-spline = velocity");
        let t = i as f64 * 2.05 / 500.0;
        close(
            bo.eval(t),
            other.eval(t)[0],
            1e-10,
            "B-spline = velocity (4 pulses)",
        );
    }
}

/// §2 (eqs. 9–12, Meckl & Seering): zero spectral content at an undamped mode leaves no
/// residual vibration; checked by exact simulation.
#[wasm_bindgen_test(unsupported = test)]
fn no_residual_vibration_on_undamped_modes() {
    for spec in [
        ProfileSpec::Pulse {
            frequency_hz: 1.0,
            distance: 1.0,
            duration: 1.7,
        },
        ProfileSpec::Triangle {
            frequency_hz: 1.0,
            distance: 1.0,
            duration: 2.3,
        },
    ] {
        let p = from_spec(&spec).unwrap();
        assert!(residual(0.0, &p) < 1e-8);
    }
    let rt = from_spec(&ProfileSpec::RobustTrapezium {
        frequency_hz: 1.0,
        delta_hz: 0.1,
        distance: 1.0,
        duration: 2.5,
    })
    .unwrap();
    let plant = ModalPlant::new(
        vec![Mode::new(1.1, 0.0).unwrap(), Mode::new(0.9, 0.0).unwrap()],
        vec![0.5, 0.5],
    )
    .unwrap();
    for v in mode_residual_percent(&plant, &rt).unwrap().unwrap() {
        assert!(v < 1e-8, "robust trapezium at f0 ± Δf: {v} %");
    }
}

/// Veciana & Cardona 2011 §3.3, Fig. 15: with the trapezium (one pulse of 1/f₀ and a final
/// pulse), "a 5 % of residual vibration is not overcome for damping ratios ζ ≤ 0.1 and for
/// durations over 1.4/f₀". Reproduces: the worst case, ζ = 0.1 at t_f = 1.4/f₀, gives 4.995 %;
/// at 1.3/f₀ it is above 5 %.
#[wasm_bindgen_test(unsupported = test)]
fn veciana_fig15_trapezium_below_5_percent() {
    let mut worst: f64 = 0.0;
    for zi in 0..=5 {
        let z = 0.02 * zi as f64;
        for ti in 0..=46 {
            let tf = 1.4 + 0.1 * ti as f64;
            let p = from_spec(&ProfileSpec::Pulse {
                frequency_hz: 1.0,
                distance: 1.0,
                duration: tf,
            })
            .unwrap();
            worst = worst.max(residual(z, &p));
        }
    }
    assert!(worst < 5.0, "worst PRV {worst} %");
    assert!(
        worst > 4.9,
        "the bound is tight in the paper too: {worst} %"
    );
    let short = from_spec(&ProfileSpec::Pulse {
        frequency_hz: 1.0,
        distance: 1.0,
        duration: 1.3,
    })
    .unwrap();
    assert!(residual(0.1, &short) > 5.0);
}

/// Veciana & Cardona 2011 §3.3, Fig. 16: "for the robust case, less than 0.7 % of residual
/// vibration is expected for damping ratios ζ ≤ 0.3". With PRV measured as here (residual
/// amplitude after the move relative to an unshaped step's, i.e. V), this holds for ζ ≤ 0.1 at
/// every duration t_f ≥ 2/f₀ (worst 0.553 % at t_f = 2/f₀), but NOT for ζ = 0.2–0.3 at short
/// durations: ζ = 0.3 gives 1.85 % at t_f = 2/f₀ and stays above 0.7 % up to t_f ≈ 2.6/f₀.
/// The paper's Fig. 16 axis range is not recoverable from the text; the residual is the
/// trapezium's factor squared (the triangle is the pulse twice), so 0.7 % for ζ = 0.3 needs
/// the trapezium's factor ≈ 8.4 %, reached only for longer moves.
#[wasm_bindgen_test(unsupported = test)]
fn veciana_fig16_robust_profile() {
    let tri = |tf: f64| {
        from_spec(&ProfileSpec::Triangle {
            frequency_hz: 1.0,
            distance: 1.0,
            duration: tf,
        })
        .unwrap()
    };
    let mut worst_01: f64 = 0.0;
    for zi in 0..=5 {
        for ti in 0..=40 {
            worst_01 = worst_01.max(residual(0.02 * zi as f64, &tri(2.0 + 0.1 * ti as f64)));
        }
    }
    assert!(worst_01 < 0.7, "ζ ≤ 0.1: {worst_01} %");
    close(residual(0.3, &tri(2.0)), 1.854, 2e-3, "ζ = 0.3 at 2/f0");
    // First duration from which ζ = 0.3 stays below 0.7 %.
    let mut from = f64::NAN;
    for ti in (0..=80).rev() {
        let tf = 2.0 + 0.05 * ti as f64;
        if residual(0.3, &tri(tf)) >= 0.7 {
            from = tf + 0.05;
            break;
        }
    }
    assert!(
        (2.5..2.7).contains(&from),
        "ζ = 0.3 below 0.7 % from {from}/f0"
    );
    // The triangle's residual is the trapezium's squared (per unit): V_tri = V_pulse².
    let z = 0.2;
    let vp = residual(
        z,
        &from_spec(&ProfileSpec::Pulse {
            frequency_hz: 1.0,
            distance: 1.0,
            duration: 1.0,
        })
        .unwrap(),
    ) / 100.0;
    close(
        residual(z, &tri(2.0)) / 100.0,
        vp * vp,
        1e-12,
        "V_tri = V_pulse²",
    );
}

/// Bad profile settings are typed errors naming the field.
#[wasm_bindgen_test(unsupported = test)]
fn bad_profiles_are_rejected() {
    let e = from_spec(&ProfileSpec::Triangle {
        frequency_hz: 1.0,
        distance: 1.0,
        duration: 1.5,
    })
    .unwrap_err();
    assert_eq!(e.field(), Some("duration"));
    let e = from_spec(&ProfileSpec::RobustTrapezium {
        frequency_hz: 1.0,
        delta_hz: 1.0,
        distance: 1.0,
        duration: 5.0,
    })
    .unwrap_err();
    assert_eq!(e.field(), Some("deltaHz"));
    let e = from_spec(&ProfileSpec::Pulse {
        frequency_hz: -1.0,
        distance: 1.0,
        duration: 5.0,
    })
    .unwrap_err();
    assert_eq!(e.field(), Some("frequencyHz"));
    assert!(matches!(
        position_from_pulses(&[0.1; 9], 1.0).unwrap_err(),
        Error::TooLarge { .. }
    ));
}

fn zero_hz(z: &[SpectrumZero]) -> Vec<f64> {
    z.iter().map(|z| z.frequency_hz).collect()
}

/// `spectrum_zeros` against the paper's closed forms: the pulse's zeros at k·f₀ (eq. 13) and
/// the final pulse's at k/(t_f − 1/f₀); the triangle's double (tangent) zero at f₀ (eq. 23,
/// p = 1); the robust trapezium's at f₀ ± Δf (Fig. 8); the multi-mode profile's at each mode
/// and at every multiple of f_cmd (eq. 28).
#[wasm_bindgen_test(unsupported = test)]
fn spectrum_zeros_match_the_papers_closed_forms() {
    let (f0, tf) = (1.5, 2.2);
    let pulse = ProfileSpec::Pulse {
        frequency_hz: f0,
        distance: 2.0,
        duration: tf,
    };
    let z = spectrum_zeros(&pulse, 5.0).unwrap();
    let fin = 1.0 / (tf - 1.0 / f0); // 0.652… Hz: 7 zeros below 5 Hz
    let mut want: Vec<(f64, bool)> = (1..=3).map(|k| (k as f64 * f0, false)).collect();
    want.extend((1..=7).map(|k| (k as f64 * fin, true)));
    want.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(z.len(), want.len(), "{z:?}");
    for (z, (f, fp)) in z.iter().zip(&want) {
        close(z.frequency_hz, *f, 1e-12, "eq. 13 zero");
        assert_eq!((z.order, z.final_pulse), (1, *fp));
    }
    let tri = spectrum_zeros(
        &ProfileSpec::Triangle {
            frequency_hz: f0,
            distance: 1.0,
            duration: 3.0,
        },
        2.0,
    )
    .unwrap();
    // 1.5 Hz twice (tangent), the final pulse (3 − 4/3 s) at 0.6, 1.2 and 1.8 Hz.
    assert_eq!(
        tri.iter().map(|z| z.order).collect::<Vec<_>>(),
        [1, 1, 2, 1]
    );
    close(tri[2].frequency_hz, f0, 1e-12, "triangle");
    close(tri[0].frequency_hz, 0.6, 1e-12, "final pulse");
    let robust = spectrum_zeros(
        &ProfileSpec::RobustTrapezium {
            frequency_hz: f0,
            delta_hz: 0.2,
            distance: 1.0,
            duration: 3.0,
        },
        f0 + 0.25,
    )
    .unwrap();
    let design: Vec<f64> = robust
        .iter()
        .filter(|z| !z.final_pulse)
        .map(|z| z.frequency_hz)
        .collect();
    assert_eq!(design.len(), 2);
    close(design[0], f0 - 0.2, 1e-12, "f0 - df");
    close(design[1], f0 + 0.2, 1e-12, "f0 + df");
    let multi = spectrum_zeros(
        &ProfileSpec::MultiMode {
            modes_hz: vec![1.2, 3.4],
            common_hz: Some(1.0),
            distance: 1.0,
            duration: 4.0,
        },
        3.5,
    )
    .unwrap();
    let design = zero_hz(
        &multi
            .iter()
            .filter(|z| !z.final_pulse)
            .copied()
            .collect::<Vec<_>>(),
    );
    for f in [1.0, 1.2, 2.0, 2.4, 3.0, 3.4] {
        assert!(
            design.iter().any(|&g| (g - f).abs() < 1e-12),
            "{f} Hz in {design:?}"
        );
    }
}

/// Independently of the closed form: the library's spectrum |U(f)| (jump form, quadrature at
/// low f) is zero at every listed zero, and every dip to zero of |U| on a fine grid is listed.
#[wasm_bindgen_test(unsupported = test)]
fn spectrum_zeros_are_the_spectrums_dips() {
    let specs = [
        ProfileSpec::Triangle {
            frequency_hz: 2.0,
            distance: 1.0,
            duration: 2.3,
        },
        ProfileSpec::RobustTrapezium {
            frequency_hz: 2.0,
            delta_hz: 0.3,
            distance: 1.0,
            duration: 1.7,
        },
        ProfileSpec::MultiMode {
            modes_hz: vec![1.2, 3.4],
            common_hz: None,
            distance: 1.0,
            duration: 2.0,
        },
    ];
    let top = 8.0;
    for spec in &specs {
        let p = from_spec(spec).unwrap();
        let zeros = zero_hz(&spectrum_zeros(spec, top).unwrap());
        for &f in &zeros {
            assert!(velocity_spectrum_at(&p, f) < 1e-9, "{spec:?}: |U({f})|");
        }
        let n = 8000;
        let df = top / n as f64;
        let u = piecewise_spectrum(
            &p,
            &SpectrumOptions {
                from_hz: df,
                to_hz: top - df,
                points: n - 1,
                signal: SpectrumSignal::Velocity,
            },
        )
        .unwrap();
        let m = &u.magnitude;
        let mut dips = 0;
        for i in 1..m.len() - 1 {
            if m[i] <= m[i - 1] && m[i] <= m[i + 1] && m[i] < 1e-3 {
                dips += 1;
                let f = u.frequency_hz[i];
                assert!(
                    zeros.iter().any(|&z| (z - f).abs() <= 2.0 * df),
                    "{spec:?}: a dip at {f} Hz ({}) not listed in {zeros:?}",
                    m[i]
                );
            }
        }
        assert!(dips * 2 >= zeros.len(), "{spec:?}: {dips} dips, {zeros:?}");
    }
}

/// Bad arguments of `spectrum_zeros` name their field.
#[wasm_bindgen_test(unsupported = test)]
fn bad_zero_requests_are_rejected() {
    let spec = ProfileSpec::Pulse {
        frequency_hz: 1.0,
        distance: 1.0,
        duration: 2.0,
    };
    assert_eq!(
        spectrum_zeros(&spec, 0.0).unwrap_err().field(),
        Some("upToHz")
    );
    assert!(matches!(
        spectrum_zeros(&spec, 1e9).unwrap_err(),
        Error::TooLarge { .. }
    ));
    let bad = ProfileSpec::Triangle {
        frequency_hz: 1.0,
        distance: 1.0,
        duration: 1.5,
    };
    assert_eq!(
        spectrum_zeros(&bad, 3.0).unwrap_err().field(),
        Some("duration")
    );
}
