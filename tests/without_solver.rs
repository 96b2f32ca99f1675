//! A build without the Cargo feature `solver`, as the page's first wasm module is built
//! (scripts/build.sh): the solved families answer [`Error::Unavailable`] (the page's design
//! worker designs them instead), every other family designs as before, and bad input to a
//! solved family is still reported at its field.
//!
//! Only compiled without the feature: scripts/test.sh runs
//! `cargo test --no-default-features --test without_solver`.
#![cfg(not(feature = "solver"))]

mod common;

use common::{close, kamel_mode, kamel_spec};
use input_shaping::design::design_for;
use input_shaping::design::sampled::SampledSpec;
use input_shaping::robustness::parameterless_specs;
use input_shaping::vibration::residual_vibration;
use input_shaping::{Error, Mode, ShaperSpec};

fn spec(json: &str) -> ShaperSpec {
    serde_json::from_str(json).unwrap()
}

fn unavailable(spec: &ShaperSpec, modes: &[Mode]) -> Error {
    let e = design_for(spec, modes).expect_err("designed without the solver");
    assert!(
        matches!(e, Error::Unavailable { .. }),
        "{spec:?}: {e:?} is not Unavailable"
    );
    e
}

#[test]
fn solved_families_are_unavailable_with_a_message() {
    let mode = Mode::new(0.5, 0.002).unwrap();
    for json in [
        // Peláez & Singhose 2002: SI with I = 0.7 at Vtol 5 %.
        r#"{"family":"si","vtol":0.05,"insensitivity":0.7}"#,
        r#"{"family":"direct"}"#,
        r#"{"family":"direct","derivatives":0}"#,
    ] {
        let e = unavailable(&spec(json), &[mode]);
        let text = e.within("shapers[1]").to_string();
        assert!(
            text.starts_with("shapers[1]: this shaper is designed by the optimisation solver"),
            "{text}"
        );
        assert!(text.contains("`solver`"), "{text}");
    }
    // Kamel et al. eq. 7 bounds that the unbounded optimum breaks (0 ≤ Aᵢ ≤ 0.1,
    // |ΔAᵢ| ≤ 0.02; tests/sampled.rs, bounds_are_met_exactly_at_the_optimum) need the QP.
    let bounded = ShaperSpec::Sampled(SampledSpec {
        amplitude_min: Some(0.0),
        amplitude_max: Some(0.1),
        increment_min: Some(-0.02),
        increment_max: Some(0.02),
        ..kamel_spec()
    });
    let e = unavailable(&bounded, &[kamel_mode()]);
    assert_eq!(e.within("shapers[0]").field(), Some("shapers[0]"));
}

/// Without active bounds the sampled family is closed form (eq. 25): designed as before, and
/// its shaper meets eq. 13 (zero residual vibration at the mode). Bounds the unbounded optimum
/// already meets do not need the QP either.
#[test]
fn sampled_without_active_bounds_is_designed() {
    let mode = kamel_mode();
    for spec in [
        kamel_spec(),
        SampledSpec {
            amplitude_min: Some(-10.0),
            amplitude_max: Some(10.0),
            ..kamel_spec()
        },
    ] {
        let shaper = design_for(&ShaperSpec::Sampled(spec), &[mode]).unwrap();
        assert_eq!(shaper.len(), 36);
        assert!(residual_vibration(&shaper, &mode) < 1e-9);
    }
}

/// Singer & Seering 1988: ZVD = [1/4, 1/2, 1/4] at 0, T/2, T for an undamped mode; and the
/// EI and negative families, which need no solver, still design.
#[test]
fn other_families_are_designed() {
    let mode = Mode::new(2.0, 0.0).unwrap();
    let zvd = design_for(&spec(r#"{"family":"zvd"}"#), &[mode]).unwrap();
    let want = [(0.0, 0.25), (0.25, 0.5), (0.5, 0.25)];
    assert_eq!(zvd.len(), 3);
    for (imp, (t, a)) in zvd.impulses().iter().zip(want) {
        close(imp.time, t, 1e-12, "ZVD time");
        close(imp.amplitude, a, 1e-12, "ZVD amplitude");
    }
    for json in [
        r#"{"family":"ei","vtol":0.05}"#,
        r#"{"family":"eihump","humps":4,"vtol":0.05}"#,
        r#"{"family":"umzvd"}"#,
        r#"{"family":"mzv"}"#,
    ] {
        let s = design_for(&spec(json), &[mode]).unwrap();
        assert!(residual_vibration(&s, &mode) < 0.05 + 1e-9, "{json}");
    }
}

/// The page's robustness background (every parameterless family but `direct`) is the same
/// without the solver: each of those families designs, for damped and undamped modes, and
/// `direct` is the only one that needs the solver.
#[test]
fn robustness_background_needs_no_solver() {
    for mode in [Mode::new(1.0, 0.0).unwrap(), Mode::new(1.0, 0.05).unwrap()] {
        for spec in parameterless_specs() {
            let designed = design_for(&spec, &[mode]);
            if matches!(spec, ShaperSpec::Direct(_)) {
                assert!(
                    matches!(designed, Err(Error::Unavailable { .. })),
                    "{designed:?}"
                );
            } else {
                assert!(designed.is_ok(), "{spec:?}: {designed:?}");
            }
        }
    }
}

/// A bad field of a solved family is reported at the field, not as Unavailable: the page shows
/// it next to the field and does not fetch the solver for a request that would fail anyway.
#[test]
fn bad_input_to_solved_families_is_reported_at_its_field() {
    let mode = Mode::new(1.0, 0.01).unwrap();
    for (json, field) in [
        (r#"{"family":"si","vtol":1.5,"insensitivity":0.3}"#, "vtol"),
        (
            r#"{"family":"si","vtol":0.05,"insensitivity":-1}"#,
            "insensitivity",
        ),
        (r#"{"family":"direct","derivatives":9}"#, "derivatives"),
        (
            r#"{"family":"direct","amplitudeMin":0.5,"amplitudeMax":0.2}"#,
            "amplitudeMin",
        ),
    ] {
        let e = design_for(&spec(json), &[mode]).expect_err(json);
        assert!(!matches!(e, Error::Unavailable { .. }), "{json}: {e:?}");
        assert_eq!(e.field(), Some(field), "{json}: {e}");
    }
}

/// The family table's `solver` column is what a build without the solver does: from each row's
/// editor defaults, a `never` family designs, an `always` family is unavailable, and the
/// `whenBounded` one (sampled, unbounded by default) designs; bounded, it is unavailable
/// (`solved_families_are_unavailable_with_a_message`).
#[test]
fn family_table_solver_column_holds_without_the_solver() {
    use input_shaping::design::{ParamDefault, ParamKind, Solver, FAMILIES};
    let mode = Mode::new(2.0, 0.05).unwrap();
    for row in FAMILIES {
        let mut spec = serde_json::Map::new();
        spec.insert("family".into(), row.name.into());
        for p in row.params {
            let value = match (p.kind, p.default) {
                (_, None) => continue,
                // A spec's counts are whole numbers.
                (ParamKind::Integer, Some(ParamDefault::Number(x))) => (x as u64).into(),
                (_, Some(d)) => serde_json::to_value(d).unwrap(),
            };
            spec.insert(p.name.into(), value);
        }
        let spec: ShaperSpec = serde_json::from_value(spec.into()).unwrap();
        let designed = design_for(&spec, &[mode]);
        match row.solver {
            Solver::Always => assert!(
                matches!(designed, Err(Error::Unavailable { .. })),
                "{}: {designed:?}",
                row.name
            ),
            Solver::Never | Solver::WhenBounded => {
                assert!(designed.is_ok(), "{}: {designed:?}", row.name)
            }
        }
    }
}
