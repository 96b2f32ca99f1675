//! Exports: exact content for a shaper whose numbers are exact in binary, and round trips.

use input_shaping::design::zero_vibration::{zv, zvd};
use input_shaping::export::{to_c_float, to_csv, to_json, to_rrf_m593};
use input_shaping::{Impulse, Mode, Shaper};
use wasm_bindgen_test::wasm_bindgen_test;

/// ZV for 2 Hz, ζ = 0: [0.5, 0.5] at [0, 0.25 s] (Singhose 2009 eqs. 14–15 with K = 1).
fn zv_2hz() -> Shaper {
    zv(&Mode::new(2.0, 0.0).unwrap()).unwrap()
}

#[wasm_bindgen_test(unsupported = test)]
fn csv_and_json_are_exact() {
    assert_eq!(to_csv(&zv_2hz()), "time_s,amplitude\n0,0.5\n0.25,0.5\n");
    assert_eq!(
        to_json(&zv_2hz()),
        r#"{"impulses":[{"time":0,"amplitude":0.5},{"time":0.25,"amplitude":0.5}],"duration":0.25}"#
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn csv_round_trips_every_bit() {
    let s = zvd(&Mode::new(37.3, 0.07).unwrap()).unwrap();
    let rows: Vec<Impulse> = to_csv(&s)
        .lines()
        .skip(1)
        .map(|l| {
            let (t, a) = l.split_once(',').unwrap();
            Impulse {
                time: t.parse().unwrap(),
                amplitude: a.parse().unwrap(),
            }
        })
        .collect();
    assert_eq!(rows, s.impulses());
}

#[wasm_bindgen_test(unsupported = test)]
fn c_array_is_exact_and_checks_the_name() {
    let c = to_c_float(&zv_2hz(), "zv_x", "ZV 2 Hz */ evil").unwrap();
    assert_eq!(
        c,
        "/* ZV 2 Hz * / evil */\n\
         /* 2 impulses, duration 0.25 s, amplitudes sum to 1 */\n\
         #define ZV_X_COUNT 2\n\
         static const float zv_x_time_s[ZV_X_COUNT] = { 0.00000000e0f, 2.50000000e-1f };\n\
         static const float zv_x_amplitude[ZV_X_COUNT] = { 5.00000000e-1f, 5.00000000e-1f };\n"
    );
    for bad in ["", "1x", "a-b", "a b", "x;int"] {
        assert_eq!(
            to_c_float(&zv_2hz(), bad, "").unwrap_err().field(),
            Some("name"),
            "{bad:?}"
        );
    }
}

/// RRF 3.6 semantics (M593 docs): H = amplitudes except the last, T = cumulative delays (s) of
/// impulses after the first.
#[wasm_bindgen_test(unsupported = test)]
fn rrf_line_follows_rrf_3_6() {
    assert_eq!(
        to_rrf_m593(&zv_2hz()).unwrap(),
        "M593 P\"custom\" H0.5 T0.25"
    );
    let s = zvd(&Mode::new(40.0, 0.1).unwrap()).unwrap();
    let line = to_rrf_m593(&s).unwrap();
    let h: Vec<f64> = line
        .split(" H")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .split(':')
        .map(|x| x.parse().unwrap())
        .collect();
    let t: Vec<f64> = line
        .split(" T")
        .nth(1)
        .unwrap()
        .split(':')
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!((h.len(), t.len()), (2, 2));
    let imp = s.impulses();
    for i in 0..2 {
        assert!((h[i] - imp[i].amplitude).abs() < 1e-6, "H{i}");
        assert!((t[i] - imp[i + 1].time).abs() < 1e-8, "T{i}");
    }
    let last = 1.0 - h.iter().sum::<f64>();
    assert!(
        (last - imp[2].amplitude).abs() < 2e-6,
        "RRF's implied last amplitude"
    );
    assert!(!line.contains('e'), "plain decimals: {line}");
}

#[wasm_bindgen_test(unsupported = test)]
fn rrf_rejects_what_it_cannot_represent() {
    let negative = Shaper::new(vec![
        Impulse {
            time: 0.0,
            amplitude: 1.0,
        },
        Impulse {
            time: 0.1,
            amplitude: -1.0,
        },
        Impulse {
            time: 0.2,
            amplitude: 1.0,
        },
    ])
    .unwrap();
    assert_eq!(
        to_rrf_m593(&negative).unwrap_err().field(),
        Some("impulses[1].amplitude")
    );
    assert!(to_rrf_m593(&Shaper::identity()).is_err());
    let half = Shaper::new(vec![
        Impulse {
            time: 0.0,
            amplitude: 0.25,
        },
        Impulse {
            time: 1.0,
            amplitude: 0.25,
        },
    ])
    .unwrap();
    assert!(to_rrf_m593(&half)
        .unwrap_err()
        .to_string()
        .contains("summing to 1"));
}

/// Fixed point: ZVD for 40 Hz, ζ = 0.1 at 8-bit resolution and a 10 µs tick. The integer
/// amplitudes sum exactly to 255 and each is within one step of A·255; ticks are round(t/tick).
#[wasm_bindgen_test(unsupported = test)]
fn c_fixed_point_rounds_exactly() {
    use input_shaping::export::to_c_fixed;
    let s = zvd(&Mode::new(40.0, 0.1).unwrap()).unwrap();
    let c = to_c_fixed(&s, "zvd_x", "ZVD 40 Hz", 255, 1e-5).unwrap();
    let array = |key: &str| -> Vec<i64> {
        let line = c.lines().find(|l| l.contains(key)).unwrap();
        line.split('{')
            .nth(1)
            .unwrap()
            .split('}')
            .next()
            .unwrap()
            .split(',')
            .map(|x| x.trim().parse().unwrap())
            .collect()
    };
    let q = array("_amplitude_q");
    let ticks = array("_time_ticks");
    assert_eq!(q.iter().sum::<i64>(), 255);
    for (k, imp) in s.impulses().iter().enumerate() {
        assert!(
            (q[k] as f64 - imp.amplitude * 255.0).abs() < 1.0,
            "amplitude {k}"
        );
        assert_eq!(ticks[k], (imp.time / 1e-5).round() as i64, "tick {k}");
    }
    assert!(c.contains("#define ZVD_X_AMPLITUDE_SCALE 255"));
    assert_eq!(
        to_c_fixed(&s, "x", "", 0, 1e-5).unwrap_err().field(),
        Some("amplitudeSteps")
    );
    assert_eq!(
        to_c_fixed(&s, "x", "", 255, -1.0).unwrap_err().field(),
        Some("tickS")
    );
}
