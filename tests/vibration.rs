//! Residual vibration V(ω, ζ), sensitivity curves and their validation.

mod common;

use common::{close, residual_by_superposition};
use input_shaping::vibration::{residual_vibration, sensitivity, SensitivityOptions};
use input_shaping::{Error, Impulse, Mode, Shaper};
use std::f64::consts::PI;
use wasm_bindgen_test::wasm_bindgen_test;

fn shaper(pairs: &[(f64, f64)]) -> Shaper {
    Shaper::new(
        pairs
            .iter()
            .map(|&(time, amplitude)| Impulse { time, amplitude })
            .collect(),
    )
    .unwrap()
}

/// A single unit impulse leaves all the vibration: V = 1 (Singhose 2009 eq. 10–11 normalisation).
#[wasm_bindgen_test(unsupported = test)]
fn unshaped_is_one() {
    for z in [0.0, 0.2, 0.9] {
        let mode = Mode::new(4.0, z).unwrap();
        close(
            residual_vibration(&Shaper::identity(), &mode),
            1.0,
            1e-15,
            "V of identity",
        );
    }
}

/// Eq. 11 agrees with an independent time-domain superposition for arbitrary (also negative)
/// shapers, frequencies and dampings.
#[wasm_bindgen_test(unsupported = test)]
fn formula_agrees_with_superposition() {
    let s = shaper(&[(0.0, 0.7), (0.13, -0.4), (0.31, 0.5), (0.5, 0.2)]);
    for z in [0.0, 0.03, 0.25, 0.6] {
        for f in [0.3, 1.0, 2.7, 11.0] {
            let mode = Mode::new(f, z).unwrap();
            close(
                residual_vibration(&s, &mode),
                residual_by_superposition(&s, &mode),
                1e-12,
                "eq. 11 vs superposition",
            );
        }
    }
}

/// The ZV sensitivity curve at ζ = 0 is |cos(πf/(2f_m))| (two equal impulses half a period apart).
#[wasm_bindgen_test(unsupported = test)]
fn zv_sensitivity_curve_is_a_cosine() {
    let s = shaper(&[(0.0, 0.5), (0.25, 0.5)]); // ZV for 2 Hz, ζ = 0
    let curve = sensitivity(
        &s,
        &SensitivityOptions {
            from_hz: 0.0,
            to_hz: 6.0,
            points: 121,
            damping: 0.0,
        },
    )
    .unwrap();
    assert_eq!(curve.frequency_hz.len(), 121);
    assert_eq!(curve.frequency_hz[0], 0.0);
    assert_eq!(curve.frequency_hz[120], 6.0);
    for (f, v) in curve.frequency_hz.iter().zip(&curve.vibration) {
        close(*v, (PI * f / 4.0).cos().abs(), 1e-12, "V(f)");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn sensitivity_rejects_bad_options() {
    let s = Shaper::identity();
    let ok = SensitivityOptions {
        from_hz: 0.0,
        to_hz: 10.0,
        points: 100,
        damping: 0.1,
    };
    let cases = [
        (
            SensitivityOptions {
                from_hz: f64::NAN,
                ..ok
            },
            "fromHz",
        ),
        (
            SensitivityOptions {
                from_hz: -1.0,
                ..ok
            },
            "fromHz",
        ),
        (SensitivityOptions { to_hz: 0.0, ..ok }, "toHz"),
        (
            SensitivityOptions {
                to_hz: f64::INFINITY,
                ..ok
            },
            "toHz",
        ),
        (SensitivityOptions { points: 1, ..ok }, "points"),
        (
            SensitivityOptions {
                points: 1_000_000_000,
                ..ok
            },
            "points",
        ),
        (SensitivityOptions { damping: 1.0, ..ok }, "damping"),
        (
            SensitivityOptions {
                damping: -0.1,
                ..ok
            },
            "damping",
        ),
    ];
    for (options, field) in cases {
        let err = sensitivity(&s, &options).unwrap_err();
        assert_eq!(err.field(), Some(field), "{err}");
        assert!(err.to_string().starts_with(field), "{err}");
    }
    assert!(matches!(
        sensitivity(
            &s,
            &SensitivityOptions {
                points: 1_000_000_000,
                ..ok
            }
        ),
        Err(Error::TooLarge { .. })
    ));
}

/// The grid recurrence is the same V as eq. 11, point by point, over long grids, with damping,
/// for negative and many-impulse shapers.
#[wasm_bindgen_test(unsupported = test)]
fn grid_recurrence_agrees_with_the_formula() {
    use input_shaping::vibration::{vibration_on_grid, vibration_rad};
    let mut seed = 12345u64;
    let mut rand = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for (n_imp, zeta) in [(2, 0.0), (5, 0.05), (40, 0.3), (300, 0.01)] {
        let s = Shaper::new(
            (0..n_imp)
                .map(|_| Impulse {
                    time: rand() * 3.0,
                    amplitude: rand() - 0.3,
                })
                .collect(),
        )
        .unwrap();
        let mut out = Vec::new();
        let (from, step, n) = (0.1, 0.0137, 3000);
        vibration_on_grid(s.impulses(), from, step, n, zeta, &mut out);
        assert_eq!(out.len(), n);
        for (k, v) in out.iter().enumerate() {
            let exact = vibration_rad(s.impulses(), 2.0 * PI * (from + step * k as f64), zeta);
            assert!(
                (v - exact).abs()
                    < 1e-12 * (1.0 + s.impulses().iter().map(|i| i.amplitude.abs()).sum::<f64>()),
                "k={k}: {v} vs {exact}"
            );
        }
    }
}

/// Long multi-mode shapers stay cheap: the band trace is bounded in work (MAX_SCAN_WORK) and still
/// brackets true crossings.
#[wasm_bindgen_test(unsupported = test)]
fn insensitivity_of_a_long_shaper_is_bounded_and_correct() {
    use input_shaping::design::zero_vibration::zv_dn;
    use input_shaping::vibration::insensitivity;
    let mut s = Shaper::identity();
    for f in [1.0, 2.3, 5.1, 11.0] {
        s = s
            .convolve(&zv_dn(&Mode::new(f, 0.02).unwrap(), 5).unwrap())
            .unwrap();
    }
    assert_eq!(s.len(), 7usize.pow(4));
    let mode = Mode::new(1.0, 0.02).unwrap();
    let band = insensitivity(&s, &mode, 0.05).unwrap();
    let v = |f: f64| residual_vibration(&s, &Mode::new(f, 0.02).unwrap());
    close(v(band.low_hz), 0.05, 1e-6, "V at the low edge");
    assert!(
        band.high_hz >= 11.0,
        "the robust bands of the four modes merge: {band:?}"
    );
}
/// The phasor used by the Newton designs has |P| = V (eq. 11) and ∂P/∂ω, ∂²P/∂ω² matching
/// central differences.
#[wasm_bindgen_test(unsupported = test)]
fn phasor_modulus_is_v_and_its_frequency_derivatives_match_differences() {
    use input_shaping::vibration::{vibration_phasor, vibration_rad};
    let s = shaper(&[(0.0, 0.7), (0.13, -0.4), (0.31, 0.5), (0.5, 0.2)]);
    for z in [0.0, 0.03, 0.25, 0.6] {
        for w in [0.5, 7.0, 19.0] {
            let p = vibration_phasor(s.impulses(), w, z);
            close(
                p.value.norm(),
                vibration_rad(s.impulses(), w, z),
                1e-14,
                "|P| = V",
            );
            let h = 1e-5;
            let (pp, pm) = (
                vibration_phasor(s.impulses(), w + h, z),
                vibration_phasor(s.impulses(), w - h, z),
            );
            let d = (pp.value - pm.value) / (2.0 * h);
            let d2 = (pp.d_omega - pm.d_omega) / (2.0 * h);
            close((d - p.d_omega).norm(), 0.0, 1e-8, "∂P/∂ω");
            close((d2 - p.d_omega2).norm(), 0.0, 1e-7, "∂²P/∂ω²");
        }
    }
}

/// Asserts `a[k] ≈ b[k]` within `tol` for every k (and equal lengths).
fn all_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (x, y) in a.iter().zip(b) {
        close(*x, *y, tol, what);
    }
}

/// A convolved shaper is analysed through its factors (V of a convolution is the product of the
/// factors' V, the transform of a convolution being the product of the transforms): every
/// analysis of the factored shaper must match the same impulses analysed directly. Cases: three
/// modes of ZVD (27 impulses from 9), and 1 Hz and 2 Hz ZVD at ζ = 0 (times 0, ½, 1 s and 0, ¼,
/// ½ s), whose sums coincide at ½ and 1 s and are merged: 7 impulses from 6.
#[wasm_bindgen_test(unsupported = test)]
fn convolved_shapers_analysed_by_factors_match_their_impulses() {
    use input_shaping::design::{design_for, ShaperSpec};
    use input_shaping::spectrum::{impulse_spectrum, SpectrumOptions};
    use input_shaping::vibration::{
        damping_insensitivity, damping_sensitivity, insensitivity, sensitivity_map,
        DampingSensitivityOptions, SensitivityMapOptions,
    };
    let cases = [
        vec![
            Mode::new(1.2, 0.012).unwrap(),
            Mode::new(3.4, 0.013).unwrap(),
            Mode::new(7.9, 0.02).unwrap(),
        ],
        vec![Mode::new(1.0, 0.0).unwrap(), Mode::new(2.0, 0.0).unwrap()],
    ];
    for (modes, (impulses, factors)) in cases.iter().zip([(27, 3), (7, 2)]) {
        let factored = design_for(&ShaperSpec::Zvd, modes).unwrap();
        let direct = Shaper::new(factored.impulses().to_vec()).unwrap();
        assert_eq!(factored.len(), impulses, "impulses after merging");
        assert_eq!(factored.factors().count(), factors, "the factors are kept");
        assert_eq!(direct.factors().count(), 1, "a shaper built from impulses");
        assert_eq!(factored, direct, "equality ignores the factors");
        let f_m = modes[0].frequency_hz();
        for mode in modes {
            for ratio in [0.37, 1.0, 1.13, 2.9] {
                let m = Mode::new(mode.frequency_hz() * ratio, mode.damping() + 0.05).unwrap();
                close(
                    residual_vibration(&factored, &m),
                    residual_vibration(&direct, &m),
                    1e-13,
                    "V",
                );
            }
            let (a, b) = (
                insensitivity(&factored, mode, 0.05).unwrap(),
                insensitivity(&direct, mode, 0.05).unwrap(),
            );
            close(a.low_hz, b.low_hz, 1e-9 * f_m, "I(Vtol) low edge");
            close(a.high_hz, b.high_hz, 1e-9 * f_m, "I(Vtol) high edge");
            let (a, b) = (
                damping_insensitivity(&factored, mode, 0.05).unwrap(),
                damping_insensitivity(&direct, mode, 0.05).unwrap(),
            );
            close(a.low_damping, b.low_damping, 1e-9, "damping band low edge");
            close(
                a.high_damping,
                b.high_damping,
                1e-9,
                "damping band high edge",
            );
            let options = DampingSensitivityOptions {
                frequency_hz: mode.frequency_hz(),
                from_damping: 0.0,
                to_damping: 0.5,
                points: 51,
            };
            let (a, b) = (
                damping_sensitivity(&factored, &options).unwrap(),
                damping_sensitivity(&direct, &options).unwrap(),
            );
            all_close(&a.vibration, &b.vibration, 1e-13, "V(ζ)");
        }
        let options = SensitivityOptions {
            from_hz: 0.0,
            to_hz: 4.0 * modes.last().unwrap().frequency_hz(),
            points: 1001,
            damping: 0.02,
        };
        let (a, b) = (
            sensitivity(&factored, &options).unwrap(),
            sensitivity(&direct, &options).unwrap(),
        );
        all_close(&a.vibration, &b.vibration, 1e-12, "V(f)");
        let options = SensitivityMapOptions {
            from_hz: 0.1,
            to_hz: 20.0,
            frequency_points: 300,
            damping_from: 0.0,
            damping_to: 0.3,
            damping_points: 7,
        };
        let (a, b) = (
            sensitivity_map(&factored, &options).unwrap(),
            sensitivity_map(&direct, &options).unwrap(),
        );
        all_close(&a.vibration, &b.vibration, 1e-12, "map");
        let options = SpectrumOptions {
            from_hz: 0.0,
            to_hz: 30.0,
            points: 600,
            signal: Default::default(),
        };
        let (a, b) = (
            impulse_spectrum(&factored, &options).unwrap(),
            impulse_spectrum(&direct, &options).unwrap(),
        );
        all_close(&a.magnitude, &b.magnitude, 1e-12, "|S(f)|");
    }
}
