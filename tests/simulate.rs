//! Simulation specs, metrics and spectra: residual vibration against V (Singhose 2009 eq. 11),
//! ramp delay against Kamel et al. eq. 10, rise and settling times against closed forms, the
//! acceleration peak-valley count (Veciana & Cardona 2011 §3.1), spectra against the shaper's,
//! and bad input.

mod common;

use common::close;
use input_shaping::command::{s_curve, step, trapezoid, Command, Interpolation, Sampled};
use input_shaping::design::zero_vibration::{zv, zvd};
use input_shaping::metrics::peak_valley_count;
use input_shaping::scenario::{run, SimulationSpec};
use input_shaping::simulate::MAX_SAMPLES;
use input_shaping::spectrum::{
    command_spectrum, impulse_spectrum, SpectrumOptions, SpectrumSignal,
};
use input_shaping::vibration::residual_vibration;
use input_shaping::{Error, Mode};
use std::f64::consts::PI;
use wasm_bindgen_test::wasm_bindgen_test;

fn spec(json: &str) -> SimulationSpec {
    serde_json::from_str(json).expect("spec parses")
}

/// One call returns both responses; a shaped step's residual equals 100·V (Singhose 2009
/// eq. 11) in the modal measure and, for an undamped mode, on the sampled endpoint too.
#[wasm_bindgen_test(unsupported = test)]
fn run_returns_unshaped_and_shaped_with_v() {
    let r = run(&spec(
        r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":1.1,"damping":0.0}]},
            "command":{"kind":"step","distance":2},
            "shaper":{"family":"zv","modes":[{"frequencyHz":1.0,"damping":0.0}]},
            "duration":5,"sampleRateHz":2000}"#,
    ))
    .unwrap();
    assert_eq!(r.time.len(), 10001);
    let shaper = zv(&Mode::new(1.0, 0.0).unwrap()).unwrap();
    let v = residual_vibration(&shaper, &Mode::new(1.1, 0.0).unwrap());
    let shaped = r.shaped.as_ref().unwrap();
    close(
        shaped.metrics.mode_residual_percent.as_ref().unwrap()[0],
        100.0 * v,
        1e-9,
        "modal PRV",
    );
    close(
        shaped.metrics.residual_vibration_percent.unwrap(),
        100.0 * v,
        1e-4,
        "sampled PRV",
    );
    close(
        r.unshaped.metrics.residual_vibration_percent.unwrap(),
        100.0,
        1e-4,
        "unshaped step: 100 %",
    );
    // Default sampling: 2000 samples, duration = move end + 3 periods of the slowest mode.
    let d = run(&spec(
        r#"{"plant":{"kind":"vecianaTestBed"},
            "command":{"kind":"trapezoid","distance":1,"maxVelocity":1,"maxAcceleration":4},
            "shaper":{"family":"zvd"}}"#,
    ))
    .unwrap();
    assert_eq!(d.time.len(), 2000);
    let s = d.shaped.as_ref().unwrap();
    let end = s.metrics.move_end;
    close(
        *d.time.last().unwrap(),
        end + 3.0 / (1.2 * (1.0f64 - 0.012 * 0.012).sqrt()),
        1e-9,
        "default duration",
    );
    // ZVD for both modes of the test bed: essentially no residual at either.
    for v in s.metrics.mode_residual_percent.as_ref().unwrap() {
        assert!(*v < 1e-7, "{v}");
    }
    assert!(d.unshaped.metrics.mode_residual_percent.as_ref().unwrap()[0] > 1.0);
    assert_eq!(d.modes_hz, vec![1.2, 3.4]);
}

/// Kamel et al. eq. 10: the ramp delay is τ = 2ζ/ω + Σ Aᵢtᵢ.
#[wasm_bindgen_test(unsupported = test)]
fn ramp_delay_is_kamel_eq_10() {
    let (f, z): (f64, f64) = (2.0, 0.1);
    let r = run(&spec(
        r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":2.0,"damping":0.1}]},
            "command":{"kind":"ramp","slope":0.5},
            "shaper":{"family":"zvd"},"duration":25,"samplePeriod":0.001}"#,
    ))
    .unwrap();
    let w = 2.0 * PI * f;
    let shaper = zvd(&Mode::new(f, z).unwrap()).unwrap();
    close(
        r.unshaped.metrics.delay.unwrap(),
        2.0 * z / w,
        1e-9,
        "plant delay",
    );
    close(
        r.shaped.unwrap().metrics.delay.unwrap(),
        2.0 * z / w + shaper.centroid_delay().unwrap(),
        1e-9,
        "τ = 2ζ/ω + Σ Aᵢtᵢ",
    );
    assert!(r.unshaped.metrics.settling_time2.is_none());
}

/// Rise time of y = 1 − cos ωt: (acos(0.1) − acos(0.9))/ω; 2 % settling of a damped step
/// against a direct search on the closed form.
#[wasm_bindgen_test(unsupported = test)]
fn rise_and_settling_times() {
    let r = run(&spec(
        r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":0.5}]},
            "command":{"kind":"step"},"duration":4,"samplePeriod":1e-5}"#,
    ))
    .unwrap();
    let w = PI;
    close(
        r.unshaped.metrics.rise_time.unwrap(),
        ((0.1f64).acos() - (0.9f64).acos()) / w,
        1e-6,
        "rise time",
    );
    let (f, z): (f64, f64) = (1.0, 0.2);
    let r = run(&spec(
        r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":1.0,"damping":0.2}]},
            "command":{"kind":"step"},"duration":6,"samplePeriod":1e-4}"#,
    ))
    .unwrap();
    let w = 2.0 * PI * f;
    let wd = w * (1.0 - z * z).sqrt();
    let y = |t: f64| {
        1.0 - (-z * w * t).exp() * ((wd * t).cos() + z / (1.0 - z * z).sqrt() * (wd * t).sin())
    };
    let mut last_out = 0.0;
    for i in 0..=600_000 {
        let t = i as f64 * 1e-5;
        if (y(t) - 1.0).abs() > 0.02 {
            last_out = t;
        }
    }
    close(
        r.unshaped.metrics.settling_time2.unwrap(),
        last_out,
        2e-4,
        "2 % settling",
    );
    assert!(r.unshaped.metrics.settling_time5.unwrap() < last_out);
}

/// Peak acceleration and jerk of the commands; Veciana & Cardona 2011 §3.1: a pulse-convolution
/// profile's acceleration has one peak and one valley (2 turning points). The paper says the
/// ZV-shaped smoothed trapezium has twice as many; its ramp durations are not given. Here,
/// with quadratic velocity ramps of 0.3 s on a 1 Hz mode, each acceleration lobe is split in
/// two by the ZV shaper (impulses ½ period apart): 6 turning points, three times as many.
#[wasm_bindgen_test(unsupported = test)]
fn peaks_and_peak_valley_counts() {
    let r = run(&spec(
        r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":1}]},
            "command":{"kind":"sCurve","distance":1,"maxVelocity":0.8,"maxAcceleration":2,"maxJerk":20},
            "duration":3}"#,
    ))
    .unwrap();
    close(
        r.unshaped.metrics.peak_acceleration.unwrap(),
        2.0,
        1e-9,
        "peak a",
    );
    close(r.unshaped.metrics.peak_jerk.unwrap(), 20.0, 1e-9, "peak j");
    let t = run(&spec(
        r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":1}]},
            "command":{"kind":"trapezoid","distance":1,"maxVelocity":0.8,"maxAcceleration":2}}"#,
    ))
    .unwrap();
    assert!(t.unshaped.metrics.peak_jerk.is_none(), "acceleration jumps");
    assert_eq!(t.unshaped.metrics.acceleration_peak_valley_count, 2);
    let proposed = run(&spec(
        r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":1}]},
            "command":{"kind":"profile","shape":"triangle","frequencyHz":1,"distance":1,"duration":3}}"#,
    ))
    .unwrap();
    assert_eq!(proposed.unshaped.metrics.acceleration_peak_valley_count, 2);
    // Smoothed trapezium: triangular acceleration lobes of 0.3 s (a never reached).
    let (v, ramp) = (0.5, 0.3);
    let j = v / (ramp / 2.0f64).powi(2);
    let smooth = s_curve(1.0, v, 100.0, j, 0.0).unwrap();
    let shaped = Command::Piecewise(
        smooth
            .shaped(&zv(&Mode::new(1.0, 0.0).unwrap()).unwrap())
            .unwrap(),
    );
    let r = run(&spec(&format!(
        r#"{{"plant":{{"kind":"modal","modes":[{{"frequencyHz":1}}]}},
            "command":{{"kind":"sCurve","distance":1,"maxVelocity":{v},"maxAcceleration":100,"maxJerk":{j}}},
            "shaper":{{"family":"zv"}}}}"#
    )))
    .unwrap();
    assert_eq!(r.shaped.unwrap().metrics.acceleration_peak_valley_count, 6);
    assert!(shaped.end_time() > 0.0);
    // The counter itself: three periods of a sine have six turning points.
    let s: Vec<f64> = (0..=3000)
        .map(|i| (i as f64 * 0.001 * 2.0 * PI).sin())
        .collect();
    assert_eq!(peak_valley_count(&s), 6);
}

/// A shaped step's velocity spectrum is D·|Σ Aᵢe^{−iωtᵢ}|, on both sides of the quadrature /
/// closed-form switch; a sampled signal's exact spectrum equals the piecewise one.
#[wasm_bindgen_test(unsupported = test)]
fn spectra_agree_with_the_shaper() {
    let shaper = zvd(&Mode::new(1.0, 0.05).unwrap()).unwrap();
    let opts = SpectrumOptions {
        from_hz: 0.0,
        to_hz: 5.0,
        points: 201,
        signal: SpectrumSignal::Velocity,
    };
    let imp = impulse_spectrum(&shaper, &opts).unwrap();
    let cmd = Command::Piecewise(step(2.0, 0.0).unwrap().shaped(&shaper).unwrap());
    let s = command_spectrum(&cmd, &opts).unwrap();
    for (a, b) in s.magnitude.iter().zip(&imp.magnitude) {
        close(*a, 2.0 * b, 1e-10, "shaped step spectrum");
    }
    // Acceleration of a trapezoid: closed form of two sinc² lobes vs quadrature near 0.
    let tr = trapezoid(1.0, 1.0, 2.0, 0.0).unwrap();
    let samples: Vec<f64> = (0..400).map(|k| tr.eval(k as f64 * 0.01)[0]).collect();
    // Linear interpolation of a trapezoid's samples is not the trapezoid; compare the sampled
    // route with the piecewise route of the same interpolated signal instead.
    let sampled = Sampled::new(0.01, samples, Interpolation::Linear).unwrap();
    let pw = Command::Piecewise(sampled.to_piecewise().unwrap());
    for signal in [
        SpectrumSignal::Position,
        SpectrumSignal::Velocity,
        SpectrumSignal::Acceleration,
    ] {
        let o = SpectrumOptions {
            from_hz: 0.01,
            to_hz: 20.0,
            points: 97,
            signal,
        };
        let a = command_spectrum(&Command::Sampled(sampled.clone()), &o).unwrap();
        let b = command_spectrum(&pw, &o).unwrap();
        for (x, y) in a.magnitude.iter().zip(&b.magnitude) {
            close(
                *x,
                *y,
                1e-8 * (1.0 + y.abs()),
                "sampled vs piecewise spectrum",
            );
        }
    }
}

/// Absurd settings are typed errors with the field; memory stays bounded.
#[wasm_bindgen_test(unsupported = test)]
fn bad_simulation_specs() {
    let base = r#""plant":{"kind":"modal","modes":[{"frequencyHz":1}]},"command":{"kind":"step"}"#;
    let e = run(&spec(&format!(r#"{{{base},"samplePeriod":-0.001}}"#))).unwrap_err();
    assert_eq!(e.field(), Some("samplePeriod"));
    let e = run(&spec(&format!(
        r#"{{{base},"duration":1e6,"samplePeriod":1e-3}}"#
    )))
    .unwrap_err();
    match e {
        Error::TooLarge { limit, .. } => assert_eq!(limit, MAX_SAMPLES as f64),
        other => panic!("expected TooLarge, got {other:?}"),
    }
    let e = run(&spec(
        r#"{"plant":{"kind":"modal","modes":[{"frequencyHz":1,"damping":1.2}]},"command":{"kind":"step"}}"#,
    ))
    .unwrap_err();
    assert_eq!(e.field(), Some("plant.modes[0].damping"));
    let e = run(&spec(&format!(
        r#"{{{base},"shaper":{{"family":"zv"}},"impulses":[{{"time":0,"amplitude":1}}]}}"#
    )))
    .unwrap_err();
    assert_eq!(e.field(), Some("impulses"));
    let e = run(&spec(&format!(
        r#"{{{base},"shaper":{{"family":"zv","modes":[{{"frequencyHz":-1}}]}}}}"#
    )))
    .unwrap_err();
    assert_eq!(e.field(), Some("shaper.modes[0].frequencyHz"));
    let e = run(&spec(
        r#"{"plant":{"kind":"twoMass","baseMass":1,"tipMass":1,"stiffness":10},"command":{"kind":"step"}}"#,
    ))
    .unwrap_err();
    assert_eq!(e.field(), Some("command"));
    let e = run(&spec(&format!(r#"{{{base},"duration":0}}"#))).unwrap_err();
    assert_eq!(e.field(), Some("duration"));
    let e = run(&spec(&format!(
        r#"{{{base},"sampleRateHz":1e9,"duration":10}}"#
    )))
    .unwrap_err();
    assert!(matches!(e, Error::TooLarge { .. }));
    assert!(serde_json::from_str::<SimulationSpec>(
        r#"{"plant":{"kind":"rocket"},"command":{"kind":"step"}}"#
    )
    .is_err());
}
