//! EI and n-hump EI: the undamped closed forms, the literature's insensitivities, and the
//! exact damped designs checked by finding the humps and zeros of V numerically.

mod common;

use common::{close, residual_by_superposition};
use input_shaping::design::extra_insensitive::{ei, ei_humps, extra_insensitive};
use input_shaping::vibration::{insensitivity, residual_vibration};
use input_shaping::{design, DesignRequest, Mode, ModeSpec, Shaper, ShaperSpec};
use std::f64::consts::PI;
use wasm_bindgen_test::wasm_bindgen_test;

const VTOLS: [f64; 4] = [0.01, 0.05, 0.1, 0.2];

fn check_times_in_half_periods(s: &Shaper, mode: &Mode) {
    let t = mode.damped_period_s();
    for (k, imp) in s.impulses().iter().enumerate() {
        close(
            imp.time,
            k as f64 * t / 2.0,
            1e-12 * t,
            "impulse time = k·T/2",
        );
    }
}

/// Singhose 2009 §3.1 (and Singhose, Seering & Singer 1990): EI at ζ = 0 is
/// [(1+V)/4, (1−V)/2, (1+V)/4] at [0, T/2, T].
#[wasm_bindgen_test(unsupported = test)]
fn ei_undamped_closed_form() {
    let mode = Mode::new(2.5, 0.0).unwrap();
    for v in VTOLS {
        let s = ei(&mode, v).unwrap();
        let want = [(1.0 + v) / 4.0, (1.0 - v) / 2.0, (1.0 + v) / 4.0];
        assert_eq!(s.len(), 3);
        for (imp, a) in s.impulses().iter().zip(want) {
            close(imp.amplitude, a, 1e-12, "EI amplitude");
        }
        check_times_in_half_periods(&s, &mode);
    }
}

/// Two-hump EI at ζ = 0 (Singhose, Porter, Tuttle & Singer 1997; the closed form as quoted in
/// Vaughan's input-shaping toolbox and Klipper's shaper_defs.py):
/// X = (V²(√(1−V²)+1))^{1/3}, A₁ = A₄ = (3X² + 2X + 3V²)/(16X), A₂ = A₃ = ½ − A₁.
#[wasm_bindgen_test(unsupported = test)]
fn two_hump_undamped_closed_form() {
    let mode = Mode::new(0.8, 0.0).unwrap();
    for v in VTOLS {
        let s = ei_humps(&mode, 2, v).unwrap();
        let x = (v * v * ((1.0 - v * v).sqrt() + 1.0)).cbrt();
        let a1 = (3.0 * x * x + 2.0 * x + 3.0 * v * v) / (16.0 * x);
        let want = [a1, 0.5 - a1, 0.5 - a1, a1];
        assert_eq!(s.len(), 4);
        for (imp, a) in s.impulses().iter().zip(want) {
            close(imp.amplitude, a, 1e-12, "two-hump amplitude");
        }
        check_times_in_half_periods(&s, &mode);
    }
}

/// Three-hump EI at ζ = 0 (Singhose et al. 1997): A₁ = A₅ = (1 + 3V + 2√(2V(V+1)))/16,
/// A₂ = A₄ = (1 − V)/4, A₃ = 1 − 2(A₁ + A₂), every T/2.
#[wasm_bindgen_test(unsupported = test)]
fn three_hump_undamped_closed_form() {
    let mode = Mode::new(13.0, 0.0).unwrap();
    for v in VTOLS {
        let s = ei_humps(&mode, 3, v).unwrap();
        let a1 = (1.0 + 3.0 * v + 2.0 * (2.0 * v * (v + 1.0)).sqrt()) / 16.0;
        let a2 = (1.0 - v) / 4.0;
        let want = [a1, a2, 1.0 - 2.0 * (a1 + a2), a2, a1];
        assert_eq!(s.len(), 5);
        for (imp, a) in s.impulses().iter().zip(want) {
            close(imp.amplitude, a, 1e-12, "three-hump amplitude");
        }
        check_times_in_half_periods(&s, &mode);
    }
}

/// Singhose 2009 §3.1 and Fig. 11: I(5 %) at ζ = 0 is 0.400 for EI, 0.725 for two-hump and
/// 0.964 for three-hump EI (one unit in the last quoted digit).
#[wasm_bindgen_test(unsupported = test)]
fn insensitivity_matches_literature() {
    let mode = Mode::new(1.0, 0.0).unwrap();
    for (humps, literature) in [(1, 0.400), (2, 0.725), (3, 0.964)] {
        let s = ei_humps(&mode, humps, 0.05).unwrap();
        let band = insensitivity(&s, &mode, 0.05).unwrap();
        close(
            band.width,
            literature,
            1e-3,
            &format!("I(5 %) of {humps}-hump EI"),
        );
    }
}

/// Golden-section search for an extremum of `g` in [a, b] (`sign` = 1 for a maximum, −1 for a
/// minimum).
fn golden(g: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64, sign: f64) -> f64 {
    let r = (5.0_f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let c = b - r * (b - a);
        let d = a + r * (b - a);
        if sign * g(c) > sign * g(d) {
            b = d;
        } else {
            a = c;
        }
    }
    0.5 * (a + b)
}

/// The humps and zeros of V(f) for 0.1 f_m … 1.95 f_m (at ζ = 0 the pattern repeats every 2 f_m),
/// found by a fine scan and refined by
/// golden-section search: zeros are local minima below 1e-6, humps the local maxima between
/// the first and last zero.
/// (frequency in Hz, V) pairs.
type Extrema = Vec<(f64, f64)>;

fn humps_and_zeros(s: &Shaper, mode: &Mode) -> (Extrema, Extrema) {
    let f_m = mode.frequency_hz();
    let z = mode.damping();
    let v = |f: f64| residual_vibration(s, &Mode::new(f, z).unwrap());
    let n = 20_000;
    let grid: Vec<f64> = (0..=n)
        .map(|i| f_m * (0.1 + 1.85 * i as f64 / n as f64))
        .collect();
    let values: Vec<f64> = grid.iter().map(|&f| v(f)).collect();
    let (mut zeros, mut maxima) = (Vec::new(), Vec::new());
    for i in 1..n {
        let (l, c, r) = (values[i - 1], values[i], values[i + 1]);
        if c <= l && c < r {
            let f = golden(&v, grid[i - 1], grid[i + 1], -1.0);
            if v(f) < 1e-6 {
                zeros.push((f, v(f)));
            }
        } else if c >= l && c > r {
            let f = golden(&v, grid[i - 1], grid[i + 1], 1.0);
            maxima.push((f, v(f)));
        }
    }
    let (lo, hi) = (zeros.first().unwrap().0, zeros.last().unwrap().0);
    let humps = maxima
        .into_iter()
        .filter(|&(f, _)| f > lo && f < hi)
        .collect();
    (humps, zeros)
}

/// With damping ζ ∈ {0, 0.05, 0.1, 0.2}: n humps exactly Vtol (to 1e-9), n + 1 zeros
/// alternating with them, the middle hump (odd n) or zero (even n) at the mode, amplitudes
/// positive and summing to 1, and the same V by time-domain superposition.
#[wasm_bindgen_test(unsupported = test)]
fn humps_are_vtol_and_zeros_between_them_with_damping() {
    for humps in 1..=3u32 {
        for z in [0.0, 0.05, 0.1, 0.2] {
            let mode = Mode::new(3.0, z).unwrap();
            let vtol = 0.05;
            let d = extra_insensitive(&mode, humps, vtol).unwrap();
            let s = &d.shaper;
            let what = format!("{humps} humps, ζ = {z}");
            assert_eq!(s.len(), humps as usize + 2, "{what}");
            close(s.amplitude_sum(), 1.0, 1e-12, &what);
            assert!(s.impulses().iter().all(|i| i.amplitude > 0.0), "{what}");
            let (found_humps, found_zeros) = humps_and_zeros(s, &mode);
            assert_eq!(found_humps.len(), humps as usize, "{what}: {found_humps:?}");
            assert_eq!(found_zeros.len(), humps as usize + 1, "{what}");
            for (k, &(f, v)) in found_humps.iter().enumerate() {
                close(v, vtol, 1e-9, &format!("{what}: hump {k}"));
                assert!(found_zeros[k].0 < f && f < found_zeros[k + 1].0, "{what}");
                close(
                    f,
                    d.humps_hz[k],
                    1e-6 * f,
                    &format!("{what}: hump location"),
                );
                let m = Mode::new(f, z).unwrap();
                close(
                    residual_by_superposition(s, &m),
                    vtol,
                    1e-9,
                    "superposition hump",
                );
            }
            for (k, &(f, v)) in found_zeros.iter().enumerate() {
                assert!(v < 1e-9, "{what}: zero {k} has V = {v}");
                close(
                    f,
                    d.zeros_hz[k],
                    1e-6 * f,
                    &format!("{what}: zero location"),
                );
                let m = Mode::new(d.zeros_hz[k], z).unwrap();
                assert!(residual_by_superposition(s, &m) < 1e-9, "{what}");
            }
            let middle = if humps % 2 == 1 {
                d.humps_hz[(humps as usize - 1) / 2]
            } else {
                d.zeros_hz[humps as usize / 2]
            };
            close(middle, 3.0, 1e-12, &format!("{what}: pinned at the mode"));
        }
    }
}

/// The damped designs against Singhose's published curve fits (Singhose, Porter, Tuttle &
/// Singer 1997 for two humps, Singhose et al. for EI at Vtol = 5 %; the polynomials as quoted
/// in Vaughan's input-shaping toolbox and Klipper's shaper_defs.py), evaluated at ζ = 0.1.
/// The fits are good to about 10⁻³; the EI fit also pins t₃ = T_d, which the exact solution
/// (same constraints, all times free) moves by 4·10⁻³ T_d.
#[wasm_bindgen_test(unsupported = test)]
fn damped_designs_agree_with_published_fits() {
    let mode = Mode::new(1.0, 0.1).unwrap();
    // Fits in ζ = 0.1, times as fractions of the undamped period 1/f.
    let two_hump_times = [0.0, 0.515_905_6, 1.008_206_2, 1.488_926_3];
    let two_hump_amps = [0.258_667_5, 0.360_119_5, 0.272_903_1, 0.108_820_6];
    let s = ei_humps(&mode, 2, 0.05).unwrap();
    for (k, imp) in s.impulses().iter().enumerate() {
        close(imp.time, two_hump_times[k], 2e-3, "two-hump time vs fit");
        close(
            imp.amplitude,
            two_hump_amps[k],
            1e-3,
            "two-hump amplitude vs fit",
        );
    }
    let td = mode.damped_period_s();
    // EI fit: a1 = 0.35488, a3 = 0.19212, t2 = 0.50470 T_d, t3 = T_d.
    let s = ei(&mode, 0.05).unwrap();
    let imp = s.impulses();
    close(imp[0].amplitude, 0.354_881_4, 1e-3, "EI A1 vs fit");
    close(imp[2].amplitude, 0.192_120_5, 1e-3, "EI A3 vs fit");
    close(imp[1].time / td, 0.504_697_6, 3e-3, "EI t2 vs fit");
    close(imp[2].time / td, 1.0, 5e-3, "EI t3 vs fit");
}

/// Four to six humps at ζ = 0 follow the Chebyshev form: equal humps, and I grows with n.
#[wasm_bindgen_test(unsupported = test)]
fn more_humps_undamped() {
    let mode = Mode::new(1.0, 0.0).unwrap();
    let mut last_width = 0.0;
    for humps in 1..=6u32 {
        let s = ei_humps(&mode, humps, 0.05).unwrap();
        let (found, zeros) = humps_and_zeros(&s, &mode);
        assert_eq!(found.len(), humps as usize);
        assert_eq!(zeros.len(), humps as usize + 1);
        for (_, v) in found {
            close(v, 0.05, 1e-9, "hump height");
        }
        close(s.duration(), (humps as f64 + 1.0) / 2.0, 1e-12, "duration");
        let w = insensitivity(&s, &mode, 0.05).unwrap().width;
        assert!(w > last_width, "I grows with n: {w} after {last_width}");
        last_width = w;
    }
}

/// A damped four-hump design at ζ = 0.05 still has four humps of exactly Vtol.
#[wasm_bindgen_test(unsupported = test)]
fn four_humps_with_damping() {
    let mode = Mode::new(7.0, 0.05).unwrap();
    let s = ei_humps(&mode, 4, 0.05).unwrap();
    let (found, zeros) = humps_and_zeros(&s, &mode);
    assert_eq!(found.len(), 4);
    assert_eq!(zeros.len(), 5);
    for (_, v) in found {
        close(v, 0.05, 1e-9, "hump height");
    }
}

fn request(modes: &[(f64, f64)], shaper: ShaperSpec) -> DesignRequest {
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

/// Spec names and defaults: `ei`, `ei2`, `ei3` with `vtol` defaulting to 0.05, and `eihump`
/// with `humps`; several modes by convolution keep V = 0 at each mode's zeros.
#[wasm_bindgen_test(unsupported = test)]
fn specs_and_multiple_modes() {
    let spec: ShaperSpec = serde_json::from_str(r#"{"family":"ei"}"#).unwrap();
    assert_eq!(spec, ShaperSpec::Ei { vtol: 0.05 });
    let spec: ShaperSpec =
        serde_json::from_str(r#"{"family":"eihump","humps":3,"vtol":0.1}"#).unwrap();
    assert_eq!(spec.name(), "eihump");
    assert!(spec.info().is_some());
    let mode = Mode::new(2.0, 0.04).unwrap();
    let direct = ei_humps(&mode, 2, 0.05).unwrap();
    let via_spec = design(&request(&[(2.0, 0.04)], ShaperSpec::Ei2 { vtol: 0.05 })).unwrap();
    assert_eq!(direct, via_spec);
    let two = design(&request(
        &[(1.0, 0.02), (2.7, 0.05)],
        ShaperSpec::Ei2 { vtol: 0.05 },
    ))
    .unwrap();
    assert_eq!(two.len(), 16);
    for (f, z) in [(1.0, 0.02), (2.7, 0.05)] {
        // Two-hump EI has a zero at the mode.
        assert!(residual_by_superposition(&two, &Mode::new(f, z).unwrap()) < 1e-9);
    }
}

/// Bad parameters name their field; a damping beyond the family's end names the mode's.
#[wasm_bindgen_test(unsupported = test)]
fn errors_name_the_field() {
    for (spec, field) in [
        (ShaperSpec::Ei { vtol: 0.0 }, "vtol"),
        (ShaperSpec::Ei { vtol: f64::NAN }, "vtol"),
        (ShaperSpec::Ei3 { vtol: 0.7 }, "vtol"),
        (
            ShaperSpec::Eihump {
                humps: 0,
                vtol: 0.05,
            },
            "humps",
        ),
        (
            ShaperSpec::Eihump {
                humps: 11,
                vtol: 0.05,
            },
            "humps",
        ),
        (ShaperSpec::Ei3 { vtol: 0.05 }, "modes[1].damping"),
    ] {
        let err = design(&request(&[(1.0, 0.0), (3.0, 0.5)], spec.clone())).unwrap_err();
        assert_eq!(err.field(), Some(field), "{spec:?}: {err}");
    }
    // EI itself exists well beyond: ζ = 0.5 is fine, with humps still exactly Vtol.
    let d = extra_insensitive(&Mode::new(1.0, 0.5).unwrap(), 1, 0.05).unwrap();
    let m = Mode::new(d.humps_hz[0], 0.5).unwrap();
    close(
        residual_vibration(&d.shaper, &m),
        0.05,
        1e-9,
        "EI at ζ = 0.5",
    );
    let _ = PI;
}
