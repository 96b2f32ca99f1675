//! Firmware configs (issue 20 item 4): exact text per firmware, every limit violated → the
//! error naming the field and the limit, numbers read back as the firmware would.
//!
//! Limits quoted from the firmware sources (read through the project's search tools):
//! - Klipper3d/klipper klippy/extras/input_shaper.py, `InputShaperParams`: `damping_ratio_*`
//!   in [0, 1], `shaper_freq_*` ≥ 0; klippy/extras/shaper_defs.py `INPUT_SHAPERS`: types zv,
//!   mzv, zvd, ei, 2hump_ei, 3hump_ei. shaper_calibrate.py prints
//!   `round(max_accel / 100.) * 100.` (Python 3: ties to even).
//! - KalicoCrew/kalico klippy/extras/input_shaper.py `CustomInputShaperParams._parse_custom_shaper`:
//!   |A| ≥ 0.001, ΣA ≥ 0.001, T ordered, equal lengths, 0.001 s ≤ duration ≤ 0.2 s;
//!   klippy/chelper/kin_shaper.c `pulses[25]`.
//! - RepRapFirmware 3.6 src/Movement/AxisShaper.h `MaxImpulses = 5`, F in [4, 400] Hz
//!   (header) and [StepClockRate/(2·65535), 1000] Hz (AxisShaper.cpp), S in [0, 0.99].
//! - Marlin Marlin/src/gcode/feature/input_shaping/M593.cpp: D in [0, 1], F > 0.

mod common;

use input_shaping::design::zero_vibration::{zv, zvd};
use input_shaping::export::firmware::{
    firmware_config, kalico_command, kalico_config, klipper_command, klipper_config,
    klipper_rounded_max_accel, marlin_config, rrf_config, AxisShaper, Firmware,
};
use input_shaping::export::to_rrf_m593;
use input_shaping::mode::ModeSpec;
use input_shaping::{Impulse, Mode, Shaper};
use wasm_bindgen_test::wasm_bindgen_test;

fn with_accel(mut a: AxisShaper, max_accel: f64) -> AxisShaper {
    a.max_accel = Some(max_accel);
    a
}

fn shaper(pairs: &[(f64, f64)]) -> Shaper {
    Shaper::new(
        pairs
            .iter()
            .map(|&(time, amplitude)| Impulse { time, amplitude })
            .collect(),
    )
    .unwrap()
}

/// The error's field and message.
fn err(
    r: input_shaping::Result<input_shaping::export::firmware::FirmwareConfig>,
) -> (String, String) {
    let e = r.unwrap_err();
    (e.field().unwrap_or("").to_string(), e.to_string())
}

/// `KEY=value` pairs of a command line.
fn params(line: &str) -> Vec<(String, String)> {
    line.split_whitespace()
        .skip(1)
        .map(|p| {
            let (k, v) = p.split_once('=').unwrap();
            (k.to_string(), v.to_string())
        })
        .collect()
}

fn value<'a>(pairs: &'a [(String, String)], key: &str) -> &'a str {
    &pairs.iter().find(|(k, _)| k == key).unwrap().1
}

/// Python 3's `round` rounds half to even: round(57.5) = 58, round(42.5) = 42, round(43.5) = 44.
#[wasm_bindgen_test(unsupported = test)]
fn max_accel_is_rounded_as_calibrate_shaper_prints_it() {
    assert_eq!(klipper_rounded_max_accel(5750.0), 5800.0);
    assert_eq!(klipper_rounded_max_accel(4250.0), 4200.0);
    assert_eq!(klipper_rounded_max_accel(4350.0), 4400.0);
    assert_eq!(klipper_rounded_max_accel(5749.9), 5700.0);
}

#[wasm_bindgen_test(unsupported = test)]
fn klipper_block_is_exact() {
    let axes = [
        with_accel(AxisShaper::named("x", "mzv", 53.8, 0.1), 5750.0),
        with_accel(AxisShaper::named("Y", "ei", 48.2, 0.1), 4250.0),
    ];
    let c = klipper_config(&axes).unwrap();
    assert_eq!(
        c.text,
        "[input_shaper]\n\
         shaper_type_x: mzv\n\
         shaper_freq_x: 53.8\n\
         damping_ratio_x: 0.1\n\
         shaper_type_y: ei\n\
         shaper_freq_y: 48.2\n\
         damping_ratio_y: 0.1\n\
         # x: mzv suggests max_accel <= 5800 mm/sec^2 (0.12 mm smoothing)\n\
         # y: ei suggests max_accel <= 4200 mm/sec^2 (0.12 mm smoothing)\n\
         # in [printer]: max_accel: 4200\n"
    );
    assert!(c.warnings.is_empty());
}

/// Without `maxAccel`, the suggestion is Klipper's figure of the given impulses.
#[wasm_bindgen_test(unsupported = test)]
fn klipper_max_accel_comes_from_the_impulses() {
    let s = zvd(&Mode::new(40.0, 0.1).unwrap()).unwrap();
    let mut a = AxisShaper::named("x", "zvd", 40.0, 0.1);
    a.impulses = Some(s.impulses().to_vec());
    let expected = klipper_rounded_max_accel(
        input_shaping::smoothing::max_accel(&s, input_shaping::smoothing::KLIPPER_SCV).unwrap(),
    );
    let text = klipper_config(&[a]).unwrap().text;
    assert!(
        text.contains(&format!(
            "# x: zvd suggests max_accel <= {expected} mm/sec^2"
        )),
        "{text}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn klipper_command_is_exact_and_reads_back() {
    let axes = [
        AxisShaper::named("x", "2hump_ei", 61.237_4, 0.083_217_3),
        AxisShaper::named("y", "zv", 37.1, 0.0),
    ];
    let c = klipper_command(&axes).unwrap();
    assert_eq!(
        c.text,
        "SET_INPUT_SHAPER SHAPER_TYPE_X=2hump_ei SHAPER_FREQ_X=61.237 \
         DAMPING_RATIO_X=0.083217 SHAPER_TYPE_Y=zv SHAPER_FREQ_Y=37.1 DAMPING_RATIO_Y=0\n"
    );
    let p = params(c.text.trim_end());
    let f: f64 = value(&p, "SHAPER_FREQ_X").parse().unwrap();
    let z: f64 = value(&p, "DAMPING_RATIO_X").parse().unwrap();
    // Klipper's own precision (input_shaper.py get_status: %.3f, %.6f).
    assert!((f - 61.237_4).abs() <= 5e-4);
    assert!((z - 0.083_217_3).abs() <= 5e-7);
}

#[wasm_bindgen_test(unsupported = test)]
fn klipper_refuses_what_it_cannot_run() {
    let cases: Vec<(AxisShaper, &str, &str)> = vec![
        (
            AxisShaper::custom("x", &zv(&Mode::new(40.0, 0.0).unwrap()).unwrap()),
            "axes[0].family",
            "no custom shaper",
        ),
        (
            AxisShaper::named("x", "zvdd", 40.0, 0.1),
            "axes[0].family",
            "Klipper has no zvdd",
        ),
        (
            AxisShaper::named("x", "si", 40.0, 0.1),
            "axes[0].family",
            "unknown shaper family",
        ),
        (
            AxisShaper::named("z", "mzv", 40.0, 0.1),
            "axes[0].axis",
            "axes x, y only",
        ),
        (
            AxisShaper::named("x", "mzv", 40.0, 1.0),
            "axes[0].damping",
            "[0, 1)",
        ),
        (
            AxisShaper::named("x", "mzv", 0.0, 0.1),
            "axes[0].frequencyHz",
            "greater than 0",
        ),
        (
            AxisShaper::named("x", "mzv", 1e-4, 0.1),
            "axes[0].frequencyHz",
            "turns shaping off",
        ),
        (
            AxisShaper::named("x", "mzv", f64::NAN, 0.1),
            "axes[0].frequencyHz",
            "finite",
        ),
    ];
    for (a, field, msg) in cases {
        let (f, m) = err(klipper_config(std::slice::from_ref(&a)));
        assert_eq!(f, field, "{m}");
        assert!(m.contains(msg), "{m}");
        assert_eq!(err(klipper_command(&[a])).0, field);
    }
    let twice = [
        AxisShaper::named("x", "zv", 40.0, 0.1),
        AxisShaper::named("X", "zv", 41.0, 0.1),
    ];
    assert_eq!(err(klipper_config(&twice)).0, "axes[1].axis");
    assert_eq!(err(klipper_config(&[])).0, "axes");
}

/// Beyond `max_damping_ratio` of shaper_defs.py (3hump_ei: 0.2) the config is written with a
/// warning.
#[wasm_bindgen_test(unsupported = test)]
fn klipper_warns_beyond_the_fitted_damping() {
    let c = klipper_config(&[AxisShaper::named("x", "3hump_ei", 50.0, 0.25)]).unwrap();
    assert_eq!(c.warnings.len(), 1);
    assert!(c.warnings[0].contains("above 0.2"), "{:?}", c.warnings);
    assert!(
        klipper_config(&[AxisShaper::named("x", "3hump_ei", 50.0, 0.2)])
            .unwrap()
            .warnings
            .is_empty()
    );
}

/// ZV at 40 Hz, ζ = 0: [0.5, 0.5] at [0, 12.5 ms] (Singhose 2009 eqs. 14–15), exact in binary.
#[wasm_bindgen_test(unsupported = test)]
fn kalico_custom_block_and_command_are_exact() {
    let s = zv(&Mode::new(40.0, 0.0).unwrap()).unwrap();
    let a = with_accel(AxisShaper::custom("x", &s), 7777.0);
    assert_eq!(
        kalico_config(std::slice::from_ref(&a)).unwrap().text,
        "[input_shaper]\n\
         shaper_type_x: custom\n\
         shaper_a_x: 0.5, 0.5\n\
         shaper_t_x: 0, 0.0125\n\
         # x: custom suggests max_accel <= 7800 mm/sec^2 (0.12 mm smoothing)\n\
         # in [printer]: max_accel: 7800\n"
    );
    assert_eq!(
        kalico_command(&[a]).unwrap().text,
        "SET_INPUT_SHAPER SHAPER_TYPE_X=custom SHAPER_A_X=0.5,0.5 SHAPER_T_X=0,0.0125\n"
    );
    // Named families are written as for Klipper.
    let named = [AxisShaper::named("y", "mzv", 53.8, 0.1)];
    assert_eq!(
        kalico_config(&named).unwrap().text,
        klipper_config(&named).unwrap().text
    );
}

/// The lists read back (Kalico's parse: split on ',' and newlines, float()) to the impulses,
/// and negative amplitudes are allowed (Kalico checks |A| only).
#[wasm_bindgen_test(unsupported = test)]
fn kalico_lists_read_back() {
    let s = shaper(&[(0.0, 0.6), (0.0071234567, -0.45), (0.0172345678, 0.85)]);
    let text = kalico_config(&[AxisShaper::custom("y", &s)]).unwrap().text;
    let list = |key: &str| -> Vec<f64> {
        let line = text.lines().find(|l| l.starts_with(key)).unwrap();
        line[key.len()..]
            .split(',')
            .map(|x| x.trim().parse().unwrap())
            .collect()
    };
    let (a, t) = (list("shaper_a_y:"), list("shaper_t_y:"));
    assert_eq!((a.len(), t.len()), (3, 3));
    for (k, imp) in s.impulses().iter().enumerate() {
        assert!(
            (a[k] - imp.amplitude).abs() <= 1e-6 * imp.amplitude.abs(),
            "A{k}"
        );
        assert!((t[k] - imp.time).abs() <= 1e-6 * imp.time.max(1e-9), "T{k}");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn kalico_limits_are_errors() {
    let custom = |s: Shaper| kalico_config(&[AxisShaper::custom("x", &s)]);
    // 26 impulses > pulses[25].
    let many: Vec<(f64, f64)> = (0..26).map(|k| (k as f64 * 0.001, 1.0 / 26.0)).collect();
    let (f, m) = err(custom(shaper(&many)));
    assert_eq!(f, "axes[0].impulses");
    assert!(m.contains("at most 25 impulses"), "{m}");
    // 25 are accepted.
    let ok: Vec<(f64, f64)> = (0..25).map(|k| (k as f64 * 0.001, 1.0 / 25.0)).collect();
    assert!(custom(shaper(&ok)).is_ok());
    // Duration 0.25 s > 0.2 s; 0.0005 s < 0.001 s.
    let (f, m) = err(custom(shaper(&[(0.0, 0.5), (0.25, 0.5)])));
    assert_eq!(f, "axes[0].impulses");
    assert!(m.contains("at most 0.2 s"), "{m}");
    assert!(custom(shaper(&[(0.0, 0.5), (0.2, 0.5)])).is_ok());
    let (_, m) = err(custom(shaper(&[(0.0, 0.5), (0.0005, 0.5)])));
    assert!(m.contains("at least 0.001 s"), "{m}");
    // |A| < 0.001.
    let (f, m) = err(custom(shaper(&[(0.0, 0.9995), (0.01, 0.0005)])));
    assert_eq!(f, "axes[0].impulses[1].amplitude");
    assert!(m.contains("0.001"), "{m}");
    // ΣA < 0.001.
    let (_, m) = err(custom(shaper(&[(0.0, 1.0), (0.01, -0.9995)])));
    assert!(m.contains("summing"), "{m}");
    // custom without impulses.
    let mut bare = AxisShaper::named("x", "custom", 40.0, 0.1);
    bare.frequency_hz = None;
    assert_eq!(err(kalico_config(&[bare])).0, "axes[0].impulses");
}

#[wasm_bindgen_test(unsupported = test)]
fn rrf_named_lines_are_exact() {
    let mzv = [
        AxisShaper::named("x", "mzv", 53.8, 0.1),
        AxisShaper::named("y", "mzv", 53.8, 0.1),
    ];
    let c = rrf_config(&mzv).unwrap();
    assert_eq!(c.text, "M593 P\"mzv\" F53.8 S0.1\n");
    assert_eq!(
        rrf_config(&[AxisShaper::named("x", "zvddd", 31.25, 0.05)])
            .unwrap()
            .text,
        "M593 P\"zvddd\" F31.25 S0.05\n"
    );
}

/// RRF times ei2 by the damped period, delay₁ = (0.49890 + 0.16270ζ − 0.54262ζ² + 6.16180ζ³) /
/// (F√(1 − ζ²)) (AxisShaper.cpp, `case InputShaperType::ei2`); Klipper's 2hump_ei by the
/// undamped one, T₁ = (same polynomial) / f (shaper_defs.py, `get_2hump_ei_shaper`). The F
/// written must make them equal.
#[wasm_bindgen_test(unsupported = test)]
fn rrf_ei2_runs_klippers_2hump_ei() {
    let (f, z) = (60.0, 0.1);
    let c = rrf_config(&[AxisShaper::named("x", "2hump_ei", f, z)]).unwrap();
    let line = c.text.lines().last().unwrap();
    assert!(line.starts_with("M593 P\"ei2\" F"), "{line}");
    assert!(
        c.text.starts_with("; ei2 runs on the damped period"),
        "{}",
        c.text
    );
    let written: f64 = line
        .split(" F")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let poly = 0.49890 + 0.16270 * z - 0.54262 * z * z + 6.16180 * z * z * z;
    let rrf_delay = poly / (written * (1.0 - z * z).sqrt());
    let klipper_delay = poly / f;
    assert!(
        (rrf_delay / klipper_delay - 1.0).abs() < 1e-5,
        "{rrf_delay} vs {klipper_delay}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn rrf_refuses_what_it_cannot_run() {
    let one = |a: AxisShaper| err(rrf_config(&[a]));
    let (f, m) = one(AxisShaper::named("x", "zv", 40.0, 0.1));
    assert_eq!(f, "axes[0].family");
    assert!(m.contains("RepRapFirmware has no zv"), "{m}");
    assert!(one(AxisShaper::named("x", "ei", 40.0, 0.1))
        .1
        .contains("no ei shaper"));
    let (f, m) = one(AxisShaper::named("x", "mzv", 401.0, 0.1));
    assert_eq!(f, "axes[0].frequencyHz");
    assert!(m.contains("400"), "{m}");
    assert!(rrf_config(&[AxisShaper::named("x", "mzv", 400.0, 0.1)]).is_ok());
    assert_eq!(
        one(AxisShaper::named("x", "mzv", 5.7, 0.1)).0,
        "axes[0].frequencyHz"
    );
    assert!(rrf_config(&[AxisShaper::named("x", "mzv", 5.73, 0.1)]).is_ok());
    let (f, m) = one(AxisShaper::named("x", "mzv", 40.0, 0.995));
    assert_eq!(f, "axes[0].damping");
    assert!(m.contains("0.99"), "{m}");
    // Six impulses > MaxImpulses = 5.
    let six: Vec<(f64, f64)> = (0..6).map(|k| (k as f64 * 0.002, 1.0 / 6.0)).collect();
    let (f, m) = one(AxisShaper::custom("x", &shaper(&six)));
    assert_eq!(f, "axes[0].impulses");
    assert!(m.contains("at most 5 impulses"), "{m}");
    assert!(to_rrf_m593(&shaper(&six)).is_err());
    let five: Vec<(f64, f64)> = (0..5).map(|k| (k as f64 * 0.002, 0.2)).collect();
    assert_eq!(
        rrf_config(&[AxisShaper::custom("x", &shaper(&five))])
            .unwrap()
            .text,
        format!("{}\n", to_rrf_m593(&shaper(&five)).unwrap())
    );
    // One shaper for all axes.
    let two = [
        AxisShaper::named("x", "mzv", 53.8, 0.1),
        AxisShaper::named("y", "mzv", 48.0, 0.1),
    ];
    let (f, m) = err(rrf_config(&two));
    assert_eq!(f, "axes[1]");
    assert!(m.contains("one input shaper for all axes"), "{m}");
}

/// The ZV Marlin runs, compared at the mode by an independent time-domain computation
/// (tests/common: superposed impulse responses).
#[wasm_bindgen_test(unsupported = test)]
fn marlin_says_what_zv_loses() {
    let design = Mode::new(53.8, 0.1).unwrap();
    let recommended = zvd(&design).unwrap();
    let mut a = AxisShaper::named("x", "zvd", 53.8, 0.1);
    a.impulses = Some(recommended.impulses().to_vec());
    a.modes = vec![ModeSpec {
        frequency_hz: 47.3,
        damping: 0.08,
    }];
    let c = marlin_config(&[a]).unwrap();
    let lines: Vec<&str> = c.text.lines().collect();
    assert_eq!(*lines.last().unwrap(), "M593 X F53.8 D0.1");
    assert_eq!(
        lines[0],
        "; x: Marlin runs ZV only; the recommendation is zvd"
    );
    let mode = Mode::new(47.3, 0.08).unwrap();
    let v_zv = common::residual_by_superposition(&zv(&design).unwrap(), &mode);
    let v_rec = common::residual_by_superposition(&recommended, &mode);
    assert_eq!(
        lines[1],
        format!(
            "; x: at the mode 47.3 Hz (damping 0.08) ZV leaves {:.1} %, zvd {:.1} %",
            100.0 * v_zv,
            100.0 * v_rec
        )
    );
    assert!(v_zv > 2.0 * v_rec, "ZV must lose here: {v_zv} vs {v_rec}");
    assert!(
        lines[2].starts_with("; x: vibration <= 5 % at damping 0.1: ZV over "),
        "{}",
        lines[2]
    );
    assert!(lines[3].contains("M493 S11"), "{}", lines[3]);
    assert_eq!(c.warnings.len(), 1);
    assert!(c.warnings[0].contains("ZV only"));
}

#[wasm_bindgen_test(unsupported = test)]
fn marlin_zv_lines_are_exact_and_check_limits() {
    let c = marlin_config(&[
        AxisShaper::named("x", "zv", 40.0, 0.15),
        AxisShaper::named("y", "zv", 35.0, 0.1),
    ])
    .unwrap();
    assert_eq!(c.text, "M593 X F40 D0.15\nM593 Y F35 D0.1\n");
    assert_eq!(c.warnings.len(), 1, "{:?}", c.warnings);
    assert!(c.warnings[0].contains("SHAPING_MIN_FREQ"));
    let mut bare = AxisShaper::custom("x", &zv(&Mode::new(40.0, 0.0).unwrap()).unwrap());
    bare.frequency_hz = None;
    assert_eq!(err(marlin_config(&[bare])).0, "axes[0].frequencyHz");
    assert_eq!(
        err(marlin_config(&[AxisShaper::named("e", "zv", 40.0, 0.1)])).0,
        "axes[0].axis"
    );
    assert_eq!(
        err(marlin_config(&[AxisShaper::named("x", "zv", 40.0, -0.1)])).0,
        "axes[0].damping"
    );
}

/// The wire form: camelCase fields, damping defaulting to Klipper's 0.1, firmware names.
#[wasm_bindgen_test(unsupported = test)]
fn dispatch_and_wire_form() {
    let axes: Vec<AxisShaper> =
        serde_json::from_str(r#"[{"axis":"x","family":"mzv","frequencyHz":53.8,"maxAccel":5750}]"#)
            .unwrap();
    assert_eq!(axes[0].damping, 0.1);
    let fw: Firmware = serde_json::from_str(r#""klipperCommand""#).unwrap();
    assert_eq!(
        firmware_config(fw, &axes).unwrap().text,
        "SET_INPUT_SHAPER SHAPER_TYPE_X=mzv SHAPER_FREQ_X=53.8 DAMPING_RATIO_X=0.1\n"
    );
    for (name, start) in [
        ("klipper", "[input_shaper]"),
        ("kalico", "[input_shaper]"),
        ("kalicoCommand", "SET_INPUT_SHAPER"),
        ("rrf", "M593 P\"mzv\""),
        ("marlin", "; x: Marlin runs ZV only"),
    ] {
        let fw: Firmware = serde_json::from_str(&format!("\"{name}\"")).unwrap();
        let text = firmware_config(fw, &axes).unwrap().text;
        assert!(text.starts_with(start), "{name}: {text}");
    }
}
