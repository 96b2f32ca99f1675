//! Integer realisation of shapers (Peláez & Singhose 2002, "Implementation of Input Shaping on
//! Flexible Machines with Integer Controllers"; equation numbers are that paper's), checked
//! against its eq. 8, hand-computed roundings and error bounds.

mod common;

use common::close;
use input_shaping::design::quantize::{
    quantize, quantize_with_report, QuantizeMethod, QuantizeOptions,
};
use input_shaping::design::sampled::{self, SampledSpec};
use input_shaping::design::zero_vibration::zvd;
use input_shaping::vibration::{residual_vibration, vibration_rad};
use input_shaping::{Error, Impulse, Mode, Shaper};
use wasm_bindgen_test::wasm_bindgen_test;

/// The SI shaper of Peláez & Singhose eq. 7 (Vtol = 5 %, I = 0.7, 0.5 Hz, ζ = 0.002).
fn eq7() -> Shaper {
    let t = [0.0, 0.9767, 1.9383, 2.9151];
    let a = [0.1560, 0.3440, 0.3440, 0.1560];
    Shaper::new(
        t.iter()
            .zip(a)
            .map(|(&time, amplitude)| Impulse { time, amplitude })
            .collect(),
    )
    .unwrap()
}

/// The paper's machine: 0.5 Hz, d = 0.002.
fn loader() -> Mode {
    Mode::new(0.5, 0.002).unwrap()
}

/// 255 PWM steps (eq. 3: G = 255/65535), a 1 ms interrupt, and c = 3.2 s / 255 steps: the value
/// eq. 8 pins (the paper does not state it; see crate::design::quantize).
fn paper_options() -> QuantizeOptions {
    QuantizeOptions {
        tick_s: Some(0.001),
        method: QuantizeMethod::UpdateTime,
        ramp_s: Some(3.2),
        ..QuantizeOptions::new(255)
    }
}

/// Eq. 8: rounding the PWM update times of eq. 7 to whole milliseconds (eq. 5) realises the
/// amplitudes 0.1569, 0.3451, 0.3346, 0.1287 — which sum to 0.9653, not 1.
#[wasm_bindgen_test(unsupported = test)]
fn update_time_rounding_reproduces_equation_8() {
    let q = quantize(&eq7(), &paper_options()).unwrap();
    let want = [0.1569, 0.3451, 0.3346, 0.1287];
    assert_eq!(q.len(), 4);
    for (imp, a) in q.impulses().iter().zip(want) {
        close(imp.amplitude, a, 5e-5, "eq. 8 amplitude (4 digits)");
    }
    close(q.amplitude_sum(), 0.9653, 5e-5, "eq. 8 sums to 0.9653");
    let times: Vec<f64> = q.impulses().iter().map(|i| i.time).collect();
    for (t, want) in times.iter().zip([0.0, 0.977, 1.938, 2.915]) {
        close(*t, want, 1e-12, "times on the 1 ms tick");
    }
    // The experiment's 3 s ramp (§3) does not give eq. 8: c matters.
    let three = quantize(
        &eq7(),
        &QuantizeOptions {
            ramp_s: Some(3.0),
            ..paper_options()
        },
    )
    .unwrap();
    assert!((three.amplitude_sum() - 0.9653).abs() > 0.01);
}

/// Fig. 6, "the shaper's robustness loss": at the mode V rises from 0.08 % (eq. 7) to 1.7 %
/// (eq. 8), and the band where V ≤ 5.5 % shrinks from 0.740 to 0.694 (numpy/brentq gives
/// 0.7401 and 0.6938). At exactly 5 % the band of eq. 7 *as printed* is split by a 5.46 % hump
/// at 0.6 Hz (its 4-digit values miss the 5 % design), so there I(5 %) = 0.479 before and
/// 0.683 after: the paper's figure cannot be read as a 5 % statement for the printed numbers.
#[wasm_bindgen_test(unsupported = test)]
fn rounding_loses_robustness_as_in_figure_6() {
    let mode = loader();
    let report = quantize_with_report(
        &eq7(),
        &mode,
        &QuantizeOptions {
            vtol: 0.055,
            ..paper_options()
        },
    )
    .unwrap();
    close(
        report.vibration_before,
        0.000757,
        1e-6,
        "V(eq. 7) at 0.5 Hz",
    );
    close(report.vibration_after, 0.01715, 1e-5, "V(eq. 8) at 0.5 Hz");
    close(
        report.insensitivity_before.width,
        0.7401,
        2e-4,
        "I(5.5 %) eq. 7",
    );
    close(
        report.insensitivity_after.width,
        0.6938,
        2e-4,
        "I(5.5 %) eq. 8",
    );
    assert!(report.insensitivity_after.width < report.insensitivity_before.width);
    close(report.amplitude_sum, 0.9653, 5e-5, "Σ A′");

    let hump = vibration_rad(eq7().impulses(), 2.0 * std::f64::consts::PI * 0.6, 0.002);
    close(hump, 0.05465, 1e-5, "eq. 7 exceeds 5 % at 0.6 Hz");
    let at5 = quantize_with_report(&eq7(), &mode, &paper_options()).unwrap();
    close(at5.insensitivity_before.width, 0.4786, 2e-4, "I(5 %) eq. 7");
    close(at5.insensitivity_after.width, 0.6826, 2e-4, "I(5 %) eq. 8");
}

/// §2: the ZVD-shaped integer profile keeps "about 97 %" of the vibration reduction with no
/// modelling error. With the same c and tick the realised ZVD leaves V = 0.9 % at the mode
/// (99.1 % reduction): at least the paper's 97 %. (Its 97 % is read from a simulated trapezoidal
/// move whose c is not given, so we do not expect the same figure.)
#[wasm_bindgen_test(unsupported = test)]
fn integer_zvd_keeps_most_of_the_reduction() {
    let mode = loader();
    let report = quantize_with_report(&zvd(&mode).unwrap(), &mode, &paper_options()).unwrap();
    assert!(report.vibration_before < 1e-12);
    assert!(
        report.vibration_after < 0.03,
        "V = {}",
        report.vibration_after
    );
    close(report.vibration_after, 0.00917, 1e-4, "numpy: 0.00917");
}

/// Largest remainder by hand: ZVD at ζ = 0 is [¼, ½, ¼]; × 255 = 63.75, 127.5, 63.75; floors
/// 63 + 127 + 63 = 253; the two missing units go to the largest remainders (0.75, 0.75), so
/// [64, 127, 64]/255, summing exactly to 255/255.
#[wasm_bindgen_test(unsupported = test)]
fn largest_remainder_by_hand() {
    let s = zvd(&Mode::new(1.0, 0.0).unwrap()).unwrap();
    let q = quantize(&s, &QuantizeOptions::new(255)).unwrap();
    let units: Vec<f64> = q.impulses().iter().map(|i| i.amplitude * 255.0).collect();
    for (u, want) in units.iter().zip([64.0, 127.0, 64.0]) {
        close(*u, want, 1e-12, "units");
    }
    // Times untouched without a tick.
    for (a, b) in q.impulses().iter().zip(s.impulses()) {
        assert_eq!(a.time, b.time);
    }
}

/// On any shaper: each kᵢ ∈ {⌊N Aᵢ⌋, ⌈N Aᵢ⌉}, Σ kᵢ = N exactly, times on the tick, and at ζ = 0
/// the change of V is bounded by the triangle inequality: Σ|ΔAᵢ| + Σ|Aᵢ| ω |Δtᵢ|.
#[wasm_bindgen_test(unsupported = test)]
fn largest_remainder_keeps_the_sum_and_bounds_the_error() {
    let mode = Mode::new(30.0 / (2.0 * std::f64::consts::PI), 0.0).unwrap();
    let designed = sampled::design(
        &mode,
        &SampledSpec {
            delay_samples: Some(17),
            plant_gain: Some(8e-4),
            ..SampledSpec::new(0.012, 36)
        },
    )
    .unwrap()
    .shaper;
    for (steps, tick) in [(255u32, 0.004), (1023, 0.001), (31, 0.0005)] {
        let options = QuantizeOptions {
            tick_s: Some(tick),
            ..QuantizeOptions::new(steps)
        };
        let q = quantize(&designed, &options).unwrap();
        let n = f64::from(steps);
        let total: f64 = q.impulses().iter().map(|i| (i.amplitude * n).round()).sum();
        assert_eq!(total, n, "Σ k = N for N = {steps}");
        let mut bound = 0.0;
        for imp in q.impulses() {
            let k = imp.amplitude * n;
            close(k, k.round(), 1e-9, "amplitude on the 1/N grid");
            let ticks = imp.time / tick;
            close(ticks, ticks.round(), 1e-9, "time on the tick");
        }
        // Pair each original impulse with its tick (times are 12 ms apart, ticks finer; the
        // first amplitude, −0.045, does not round to 0 at these N, so nothing shifts).
        let ticks_of = |t: f64| (t / tick).round() * tick;
        let offset = 0.0;
        for orig in designed.impulses() {
            let t = ticks_of(orig.time) - offset;
            let rounded = q
                .impulses()
                .iter()
                .find(|i| (i.time - t).abs() < 1e-12)
                .map_or(0.0, |i| i.amplitude);
            let k = orig.amplitude * n;
            assert!(
                (rounded * n - k.floor()).abs() < 1e-9 || (rounded * n - k.ceil()).abs() < 1e-9,
                "k ∈ {{floor, ceil}} for A = {}",
                orig.amplitude
            );
            bound += (rounded - orig.amplitude).abs()
                + orig.amplitude.abs() * mode.omega_rad_s() * (t - orig.time).abs();
        }
        let v = residual_vibration(&q, &mode);
        assert!(v <= bound + 1e-12, "V = {v} > bound {bound} (N = {steps})");
    }
}

/// An amplitude that rounds to 0 is dropped; if it was the first, the shaper starts at the next
/// impulse (V is unchanged by the shift).
#[wasm_bindgen_test(unsupported = test)]
fn leading_zero_is_dropped() {
    let s = Shaper::new(vec![
        Impulse {
            time: 0.0,
            amplitude: 0.01,
        },
        Impulse {
            time: 0.3,
            amplitude: 0.52,
        },
        Impulse {
            time: 0.5,
            amplitude: 0.47,
        },
    ])
    .unwrap();
    let q = quantize(&s, &QuantizeOptions::new(10)).unwrap();
    assert_eq!(q.len(), 2);
    close(q.impulses()[0].amplitude, 0.5, 1e-15, "0.52 → 5/10");
    close(q.impulses()[1].time, 0.2, 1e-15, "shifted by 0.3 s");
    close(q.amplitude_sum(), 1.0, 1e-15, "Σ 10/10");
}

/// Bad options name their field; a level faster than one step per tick is infeasible.
#[wasm_bindgen_test(unsupported = test)]
fn bad_options_name_their_field() {
    let s = eq7();
    let field = |o: QuantizeOptions| quantize(&s, &o).unwrap_err().field().map(str::to_string);
    assert_eq!(
        field(QuantizeOptions::new(0)).as_deref(),
        Some("amplitudeSteps")
    );
    assert_eq!(
        field(QuantizeOptions::new(u32::MAX)).as_deref(),
        Some("amplitudeSteps")
    );
    assert_eq!(
        field(QuantizeOptions {
            tick_s: Some(-1.0),
            ..QuantizeOptions::new(255)
        })
        .as_deref(),
        Some("tickS")
    );
    assert_eq!(
        field(QuantizeOptions {
            tick_s: None,
            ..paper_options()
        })
        .as_deref(),
        Some("tickS")
    );
    assert_eq!(
        field(QuantizeOptions {
            ramp_s: None,
            ..paper_options()
        })
        .as_deref(),
        Some("rampS")
    );
    assert_eq!(
        field(QuantizeOptions {
            tick_s: Some(1e-300),
            ..QuantizeOptions::new(255)
        })
        .as_deref(),
        Some("tickS")
    );
    // One step: the single unit goes to the largest remainder (the first 0.344), so Σ = 1.
    let q = quantize(&s, &QuantizeOptions::new(1)).unwrap();
    close(q.amplitude_sum(), 1.0, 0.0, "a single step keeps the sum");
    assert_eq!(q.len(), 1);
    close(q.impulses()[0].amplitude, 1.0, 0.0, "all on one impulse");
    assert!(matches!(
        quantize(
            &s,
            &QuantizeOptions {
                ramp_s: Some(0.1),
                ..paper_options()
            }
        ),
        Err(Error::Infeasible { .. })
    ));
    let mode = loader();
    let err = quantize_with_report(
        &s,
        &mode,
        &QuantizeOptions {
            vtol: 2.0,
            ..QuantizeOptions::new(255)
        },
    )
    .unwrap_err();
    assert_eq!(err.field(), Some("vtol"));
}
