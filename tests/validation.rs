//! Bad input gives typed errors that name the field; nothing panics.

use input_shaping::vibration::insensitivity;
use input_shaping::{design, DesignRequest, Error, Impulse, Mode, ModeSpec, Shaper, ShaperSpec};
use wasm_bindgen_test::wasm_bindgen_test;

#[wasm_bindgen_test(unsupported = test)]
fn mode_rejects_out_of_domain_values() {
    let bad = [
        (f64::NAN, 0.1, "frequencyHz"),
        (f64::INFINITY, 0.1, "frequencyHz"),
        (-2.0, 0.1, "frequencyHz"),
        (0.0, 0.1, "frequencyHz"),
        (1e-320, 0.1, "frequencyHz"),
        (1e12, 0.1, "frequencyHz"),
        (2.0, 1.0, "damping"),
        (2.0, 1.5, "damping"),
        (2.0, -0.01, "damping"),
        (2.0, f64::NAN, "damping"),
    ];
    for (f, z, field) in bad {
        let err = Mode::new(f, z).unwrap_err();
        assert_eq!(err.field(), Some(field), "{f} {z}: {err}");
    }
    assert!(Mode::new(2.0, 0.999).is_ok());
}

#[wasm_bindgen_test(unsupported = test)]
fn mode_list_names_the_index() {
    let err = Mode::list(&[
        ModeSpec {
            frequency_hz: 1.0,
            damping: 0.0,
        },
        ModeSpec {
            frequency_hz: 2.0,
            damping: 2.0,
        },
    ])
    .unwrap_err();
    assert_eq!(err.field(), Some("modes[1].damping"));
    assert_eq!(Mode::list(&[]).unwrap_err().field(), Some("modes"));
    let dup = ModeSpec {
        frequency_hz: 1.0,
        damping: 0.1,
    };
    assert_eq!(
        Mode::list(&[dup, dup]).unwrap_err().field(),
        Some("modes[1]")
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn shaper_is_sorted_merged_and_starts_at_zero() {
    let s = Shaper::new(vec![
        Impulse {
            time: 3.0,
            amplitude: 0.25,
        },
        Impulse {
            time: 1.0,
            amplitude: 0.5,
        },
        Impulse {
            time: 3.0,
            amplitude: 0.25,
        },
    ])
    .unwrap();
    assert_eq!(
        s.impulses(),
        &[
            Impulse {
                time: 0.0,
                amplitude: 0.5
            },
            Impulse {
                time: 2.0,
                amplitude: 0.5
            }
        ]
    );
    assert_eq!(s.duration(), 2.0);
    assert_eq!(s.centroid_delay(), Some(1.0));
}

#[wasm_bindgen_test(unsupported = test)]
fn shaper_rejects_bad_impulses() {
    let imp = |time, amplitude| Impulse { time, amplitude };
    assert_eq!(Shaper::new(vec![]).unwrap_err().field(), Some("impulses"));
    assert_eq!(
        Shaper::new(vec![imp(0.0, 1.0), imp(f64::NAN, 1.0)])
            .unwrap_err()
            .field(),
        Some("impulses[1].time")
    );
    assert_eq!(
        Shaper::new(vec![imp(0.0, f64::INFINITY)])
            .unwrap_err()
            .field(),
        Some("impulses[0].amplitude")
    );
    assert_eq!(
        Shaper::new(vec![imp(-1.0, 1.0)]).unwrap_err().field(),
        Some("impulses[0].time")
    );
    assert_eq!(
        Shaper::new(vec![imp(0.0, 0.0)]).unwrap_err().field(),
        Some("impulses")
    );
    assert!(matches!(
        Shaper::new(vec![imp(0.0, 1.0); 5000]),
        Err(Error::TooLarge { .. })
    ));
}

#[wasm_bindgen_test(unsupported = test)]
fn design_errors_name_the_mode() {
    let request = DesignRequest {
        modes: vec![ModeSpec {
            frequency_hz: -3.0,
            damping: 0.1,
        }],
        shaper: ShaperSpec::Zv,
    };
    let err = design(&request).unwrap_err();
    assert_eq!(err.field(), Some("modes[0].frequencyHz"));
    assert!(err.to_string().contains("greater than 0"), "{err}");
}

/// Convolving per-mode shapers is bounded: many modes of a long family give TooLarge, not OOM.
#[wasm_bindgen_test(unsupported = test)]
fn convolution_size_is_bounded() {
    let modes: Vec<ModeSpec> = (1..=12)
        .map(|i| ModeSpec {
            frequency_hz: i as f64 * 1.37,
            damping: 0.01,
        })
        .collect();
    let err = design(&DesignRequest {
        modes,
        shaper: ShaperSpec::Zvdn { derivatives: 3 },
    })
    .unwrap_err();
    assert!(matches!(err, Error::TooLarge { .. }), "{err}");
}

#[wasm_bindgen_test(unsupported = test)]
fn insensitivity_rejects_bad_vtol_and_reports_empty_bands() {
    let mode = Mode::new(1.0, 0.0).unwrap();
    for vtol in [0.0, -0.1, 1.0, f64::NAN] {
        assert_eq!(
            insensitivity(&Shaper::identity(), &mode, vtol)
                .unwrap_err()
                .field(),
            Some("vtol")
        );
    }
    let band = insensitivity(&Shaper::identity(), &mode, 0.05).unwrap();
    assert_eq!((band.width, band.low_hz, band.high_hz), (0.0, 1.0, 1.0));
}

/// The page's design worker designs with `design_solved_for` (Cargo feature `js-designer`):
/// for the solved families it is `design_for`, impulse for impulse and error for error; every
/// other family is refused at `family`.
#[wasm_bindgen_test(unsupported = test)]
fn design_solved_for_is_design_for_on_the_solved_families_only() {
    use input_shaping::design::{design_for, design_solved_for};
    let spec = |json: &str| -> ShaperSpec { serde_json::from_str(json).unwrap() };
    // Peláez & Singhose 2002's carrousel (0.5 Hz, ζ 0.002, SI with I = 0.7 at 5 %); the page's
    // two-mode preset (1 and 2.7 Hz); Kamel, Lange & Hirzinger's robot joint (ω = 30 rad/s,
    // ζ = 0.02, T = 12 ms, 36 impulses, m = 17, K = 8e-4).
    let pelaez = [Mode::new(0.5, 0.002).unwrap()];
    let two = [Mode::new(1.0, 0.02).unwrap(), Mode::new(2.7, 0.02).unwrap()];
    let kamel = [Mode::new(30.0 / std::f64::consts::TAU, 0.02).unwrap()];
    let sampled =
        r#"{"family":"sampled","periodS":0.012,"impulses":36,"delaySamples":17,"plantGain":8e-4"#;
    let cases: [(String, &[Mode]); 6] = [
        (
            r#"{"family":"si","vtol":0.05,"insensitivity":0.7}"#.into(),
            &pelaez,
        ),
        (
            r#"{"family":"si","vtol":0.05,"insensitivity":0.3}"#.into(),
            &two,
        ),
        (r#"{"family":"direct","derivatives":1}"#.into(), &two),
        (format!("{sampled}}}"), &kamel),
        (format!(r#"{sampled},"amplitudeMin":0}}"#), &kamel),
        // Infeasible (a 0.5 Hz period is 2 s): the same error from both.
        (
            r#"{"family":"si","vtol":0.05,"insensitivity":0.7,"maxDuration":0.5}"#.into(),
            &pelaez,
        ),
    ];
    for (i, (json, modes)) in cases.iter().enumerate() {
        let s = spec(json);
        match (design_for(&s, modes), design_solved_for(&s, modes)) {
            (Ok(a), Ok(b)) if i < 5 => assert_eq!(a.impulses(), b.impulses(), "{json}"),
            (Err(a), Err(b)) if i == 5 => assert_eq!(a.to_string(), b.to_string(), "{json}"),
            (a, b) => panic!("{json}: {a:?} vs {b:?}"),
        }
    }
    for json in [
        r#"{"family":"zvd"}"#,
        r#"{"family":"ei","vtol":0.05}"#,
        r#"{"family":"custom","impulses":[{"time":0,"amplitude":1}]}"#,
    ] {
        let e = design_solved_for(&spec(json), &pelaez).unwrap_err();
        assert_eq!(e.field(), Some("family"), "{json}: {e}");
        assert!(design_for(&spec(json), &pelaez).is_ok(), "{json}");
    }
}
