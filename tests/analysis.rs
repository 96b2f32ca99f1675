//! Sensitivity over damping, the frequency × damping map, damping insensitivity and the
//! robustness–duration table, against closed forms and the literature.
//! Runs natively (`cargo test`) and in wasm (`wasm-pack test`).

mod common;

use common::{close, residual_by_superposition};
use input_shaping::design::zero_vibration::{zv, zv_dn, zvd};
use input_shaping::robustness::{parameterless_specs, robustness_table, MAX_TABLE_ROWS};
use input_shaping::vibration::{
    damping_insensitivity, damping_sensitivity, sensitivity, sensitivity_map, vibration_rad,
    DampingSensitivityOptions, SensitivityMapOptions, SensitivityOptions, MAP_RESEED,
    MAX_BAND_DAMPING,
};
use input_shaping::{design::FAMILIES, Error, Impulse, Mode, Shaper, ShaperSpec};
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

/// The 9-impulse shaper of the benchmark: ZVD for 1 Hz, ζ = 0.05 convolved with ZVD for
/// 2.7 Hz, ζ = 0.02 (Singer & Seering 1988 §2.3).
fn two_mode_zvd() -> Shaper {
    let a = zvd(&Mode::new(1.0, 0.05).unwrap()).unwrap();
    let b = zvd(&Mode::new(2.7, 0.02).unwrap()).unwrap();
    a.convolve(&b).unwrap()
}

/// Shapers the fast map path is checked on: positive and multi-mode, negative amplitudes at
/// irregular times, and amplitudes near the top of the f64 range (C² + S² would overflow
/// without the map's rescaling).
fn test_shapers() -> Vec<(&'static str, Shaper)> {
    vec![
        ("two-mode ZVD", two_mode_zvd()),
        (
            "negative, irregular",
            shaper(&[
                (0.0, 1.3),
                (0.071, -0.9),
                (0.33, 0.75),
                (0.61, -0.4),
                (1.2, 0.25),
            ]),
        ),
        (
            "huge amplitudes",
            // At the largest amplitude a shaper accepts (shaper::MAX_AMPLITUDE = 1e12).
            shaper(&[(0.0, 1e12), (0.2, -7e11), (0.45, 3e11)]),
        ),
    ]
}

/// ZV designed for (f_m, ζ_m), evaluated at the model frequency on a plant of damping ζ, in
/// closed form. Derivation (Singhose 2009 eqs. 11, 14–15): ZV is A₁ = 1/(1+K), A₂ = K/(1+K) at
/// t₂ = π/(ω_m√(1−ζ_m²)), K = exp(−πζ_m/√(1−ζ_m²)). On the plant (ω_m, ζ), eq. 11 gives
/// V = e^{−ζω_m t₂} |A₁ + A₂ e^{ζω_m t₂} e^{iω_m√(1−ζ²) t₂}| = |A₁ e^{−β} + A₂ e^{iφ}| with
/// β = πζ/√(1−ζ_m²) and φ = π√(1−ζ²)/√(1−ζ_m²); so
/// V² = A₁² e^{−2β} + A₂² + 2A₁A₂ e^{−β} cos φ. At ζ = ζ_m: e^{−β} = K, φ = π, V = 0.
fn zv_damping_mismatch(zeta_m: f64, zeta: f64) -> f64 {
    let root_m = (1.0 - zeta_m * zeta_m).sqrt();
    let k = (-PI * zeta_m / root_m).exp();
    let (a1, a2) = (1.0 / (1.0 + k), k / (1.0 + k));
    let beta = PI * zeta / root_m;
    let phi = PI * (1.0 - zeta * zeta).sqrt() / root_m;
    let e = (-beta).exp();
    (a1 * a1 * e * e + a2 * a2 + 2.0 * a1 * a2 * e * phi.cos())
        .max(0.0)
        .sqrt()
}

/// Root of `g` in [lo, hi] by plain bisection (g(lo) ≤ 0 < g(hi)), for the tests' own
/// reference values.
fn root(g: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    assert!(g(lo) <= 0.0 && g(hi) > 0.0, "not a bracket: {lo} {hi}");
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) > 0.0 {
            hi = mid
        } else {
            lo = mid
        }
    }
    0.5 * (lo + hi)
}

fn map_options(
    from_hz: f64,
    to_hz: f64,
    frequency_points: usize,
    damping_from: f64,
    damping_to: f64,
    damping_points: usize,
) -> SensitivityMapOptions {
    SensitivityMapOptions {
        from_hz,
        to_hz,
        frequency_points,
        damping_from,
        damping_to,
        damping_points,
    }
}

/// Row ζ = 0 of the map of a ZV shaper for an undamped mode is |cos(πf/(2f_m))| (two equal
/// impulses half a period apart, Singhose 2009 eqs. 11, 14–15 with K = 1), and the grid axes
/// are the evenly spaced values asked for, ends included.
#[wasm_bindgen_test(unsupported = test)]
fn zv_map_row_at_zero_damping_is_a_cosine() {
    let s = zv(&Mode::new(2.0, 0.0).unwrap()).unwrap();
    let map = sensitivity_map(&s, &map_options(0.0, 6.0, 121, 0.0, 0.3, 4)).unwrap();
    assert_eq!(map.frequency_hz.len(), 121);
    for (z, want) in map.damping.iter().zip([0.0, 0.1, 0.2, 0.3]) {
        close(*z, want, 1e-15, "damping axis");
    }
    assert_eq!((map.damping[0], map.damping[3]), (0.0, 0.3));
    assert_eq!(map.vibration.len(), 121 * 4);
    assert_eq!((map.frequency_hz[0], map.frequency_hz[120]), (0.0, 6.0));
    for (j, &f) in map.frequency_hz.iter().enumerate() {
        close(
            map.get(0, j).unwrap(),
            (PI * f / 4.0).cos().abs(),
            1e-12,
            "V(f, 0)",
        );
    }
    // With damping the notch fills in: V(f_m, ζ) > 0 for ζ > 0 (closed form above).
    let j_m = 40; // 2 Hz
    close(map.frequency_hz[j_m], 2.0, 1e-15, "grid");
    for k in 1..4 {
        close(
            map.get(k, j_m).unwrap(),
            zv_damping_mismatch(0.0, map.damping[k]),
            1e-12,
            "V(f_m, ζ)",
        );
    }
    assert_eq!(map.get(4, 0), None);
    assert_eq!(map.get(0, 121), None);
}

/// The fast path against the definition: every row of the map equals `sensitivity` (which
/// calls `vibration_rad` point by point) at that damping, to 1e-12 relative to Σ|Aᵢ|, over rows
/// long enough to cross several re-seeding blocks (2000 points = 7.8 × MAP_RESEED) and
/// dampings up to 0.95.
#[wasm_bindgen_test(unsupported = test)]
fn map_rows_equal_sensitivity_curves_at_each_damping() {
    const { assert!(2000 > 7 * MAP_RESEED) };
    for (name, s) in test_shapers() {
        let scale: f64 = s.impulses().iter().map(|i| i.amplitude.abs()).sum();
        for (from_hz, to_hz) in [(0.0, 12.0), (0.37, 3.1)] {
            let options = map_options(from_hz, to_hz, 2000, 0.0, 0.95, 6);
            let map = sensitivity_map(&s, &options).unwrap();
            for (k, &zeta) in map.damping.iter().enumerate() {
                let curve = sensitivity(
                    &s,
                    &SensitivityOptions {
                        from_hz,
                        to_hz,
                        points: 2000,
                        damping: zeta,
                    },
                )
                .unwrap();
                assert_eq!(curve.frequency_hz, map.frequency_hz);
                let row = map.row(k).unwrap();
                let worst = row
                    .iter()
                    .zip(&curve.vibration)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(
                    worst <= 1e-12 * scale,
                    "{name}, ζ = {zeta}, {from_hz}…{to_hz} Hz: max |Δ| = {worst:e} (Σ|A| = {scale:e})"
                );
            }
        }
    }
}

/// Columns of the map equal the damping sensitivity curve at that frequency; both agree with
/// an independent time-domain superposition at a few points (tests/common).
#[wasm_bindgen_test(unsupported = test)]
fn map_columns_equal_damping_curves() {
    let s = two_mode_zvd();
    let map = sensitivity_map(&s, &map_options(0.2, 5.0, 25, 0.01, 0.6, 30)).unwrap();
    for j in [0, 7, 24] {
        let f = map.frequency_hz[j];
        let curve = damping_sensitivity(
            &s,
            &DampingSensitivityOptions {
                frequency_hz: f,
                from_damping: 0.01,
                to_damping: 0.6,
                points: 30,
            },
        )
        .unwrap();
        assert_eq!(curve.damping, map.damping);
        for (k, &v) in curve.vibration.iter().enumerate() {
            close(map.get(k, j).unwrap(), v, 1e-12, "map column vs V(ζ)");
        }
        for k in [0, 13, 29] {
            let mode = Mode::new(f, curve.damping[k]).unwrap();
            close(
                curve.vibration[k],
                residual_by_superposition(&s, &mode),
                1e-12,
                "V(ζ) vs superposition",
            );
        }
    }
}

/// V over damping at the model frequency for ZV with a damping mismatch matches the closed form
/// derived at `zv_damping_mismatch` (Singhose 2009 eqs. 11, 14–15), and vanishes at ζ_m.
#[wasm_bindgen_test(unsupported = test)]
fn zv_damping_sensitivity_matches_closed_form() {
    for (f_m, zeta_m) in [(1.0, 0.0), (2.0, 0.1), (0.5, 0.3)] {
        let s = zv(&Mode::new(f_m, zeta_m).unwrap()).unwrap();
        let curve = damping_sensitivity(
            &s,
            &DampingSensitivityOptions {
                frequency_hz: f_m,
                from_damping: 0.0,
                to_damping: 0.9,
                points: 181,
            },
        )
        .unwrap();
        assert_eq!(curve.damping.len(), 181);
        for (&z, &v) in curve.damping.iter().zip(&curve.vibration) {
            close(v, zv_damping_mismatch(zeta_m, z), 1e-12, "V(ζ) of ZV");
        }
        let at_model = vibration_rad(s.impulses(), 2.0 * PI * f_m, zeta_m);
        assert!(at_model < 1e-12, "V(ζ_m) = {at_model}");
    }
}

/// Convolution multiplies V at every (ω, ζ) (Singer & Seering 1988 §2.3; eq. 11 of a
/// convolution factors), so ZVD = ZV * ZV has V(ζ) equal to the square of ZV's closed form.
#[wasm_bindgen_test(unsupported = test)]
fn zvd_damping_sensitivity_is_zv_squared() {
    let zeta_m = 0.05;
    let s = zvd(&Mode::new(1.5, zeta_m).unwrap()).unwrap();
    let curve = damping_sensitivity(
        &s,
        &DampingSensitivityOptions {
            frequency_hz: 1.5,
            from_damping: 0.0,
            to_damping: 0.5,
            points: 51,
        },
    )
    .unwrap();
    for (&z, &v) in curve.damping.iter().zip(&curve.vibration) {
        close(
            v,
            zv_damping_mismatch(zeta_m, z).powi(2),
            1e-12,
            "V(ζ) of ZVD",
        );
    }
}

/// The damping band of ZV: its edges are where the closed form crosses Vtol, found here by an
/// independent bisection. For ζ_m = 0 the band starts at ζ = 0 (the search limit) and ends near
/// ζ ≈ 2·Vtol/π (first order: V ≈ πζ/2).
#[wasm_bindgen_test(unsupported = test)]
fn zv_damping_insensitivity_edges_match_closed_form() {
    let vtol = 0.05;
    let s = zv(&Mode::new(1.0, 0.0).unwrap()).unwrap();
    let band = damping_insensitivity(&s, &Mode::new(1.0, 0.0).unwrap(), vtol).unwrap();
    let high = root(|z| zv_damping_mismatch(0.0, z) - vtol, 0.0, 0.2);
    assert_eq!(band.low_damping, 0.0);
    close(band.high_damping, high, 1e-9, "upper edge, ζ_m = 0");
    close(band.width, high, 1e-9, "width");
    assert!((high - 2.0 * vtol / PI).abs() < 2e-3, "first order: {high}");

    let zeta_m = 0.1;
    let mode = Mode::new(2.0, zeta_m).unwrap();
    let s = zv(&mode).unwrap();
    let band = damping_insensitivity(&s, &mode, vtol).unwrap();
    let g = |z: f64| zv_damping_mismatch(zeta_m, z) - vtol;
    let high = root(g, zeta_m, 0.3);
    let low = root(|z| g(zeta_m - z), 0.0, zeta_m); // bisection on the mirrored side
    close(band.high_damping, high, 1e-9, "upper edge, ζ_m = 0.1");
    close(
        band.low_damping,
        zeta_m - low,
        1e-9,
        "lower edge, ζ_m = 0.1",
    );
    close(
        band.width,
        band.high_damping - band.low_damping,
        1e-15,
        "width",
    );

    // V above Vtol at the mode itself: an empty band at the mode's damping.
    let off = Mode::new(1.3, 0.2).unwrap();
    let empty = damping_insensitivity(&s, &off, vtol).unwrap();
    assert_eq!(
        (empty.low_damping, empty.high_damping, empty.width),
        (0.2, 0.2, 0.0)
    );
}

/// The page designs its robustness background once per (ζ, Vtol) at 1 Hz and rescales the
/// seconds (crate/js/api.rs `robustness_rows`): every parameterless family's durations in
/// periods and insensitivities must then not depend on the mode's frequency. Checked for
/// frequencies two decades apart, at a damped mode, against the table designed at each.
#[wasm_bindgen_test(unsupported = test)]
fn robustness_table_is_frequency_invariant_at_fixed_damping() {
    let specs = parameterless_specs();
    let at = |f: f64| robustness_table(&specs, &Mode::new(f, 0.05).unwrap(), 0.05).unwrap();
    let unit = at(1.0);
    for f in [0.37, 45.0] {
        let rows = at(f);
        let period = Mode::new(f, 0.05).unwrap().damped_period_s();
        assert_eq!(rows.len(), unit.len());
        for (r, u) in rows.iter().zip(&unit) {
            assert_eq!((&r.spec, r.impulses), (&u.spec, u.impulses), "{}", r.title);
            let what = format!("{} at {f} Hz", r.title);
            close(r.duration_periods, u.duration_periods, 1e-6, &what);
            close(r.duration_s, u.duration_periods * period, 1e-6, &what);
            close(r.insensitivity, u.insensitivity, 1e-6, &what);
            close(
                r.damping_insensitivity,
                u.damping_insensitivity,
                1e-6,
                &what,
            );
        }
    }
}

/// Singhose 2009 Fig. 11 for the zero-derivative shapers at ζ = 0: ZV-Dⁿ lasts (n+1)/2 periods
/// and, since it is ZV convolved n+1 times, V = |cos(πf/(2f_m))|ⁿ⁺¹, so
/// I(Vtol) = (4/π)·asin(Vtol^{1/(n+1)}): 0.0637 for ZV and 0.2871 for ZVD, which the paper's
/// text rounds to 0.06 and 0.286 (§2, §3).
#[wasm_bindgen_test(unsupported = test)]
fn robustness_table_matches_fig_11_for_zero_derivative_shapers() {
    let mode = Mode::new(4.0, 0.0).unwrap();
    let specs: Vec<ShaperSpec> = (0..4)
        .map(|n| ShaperSpec::Zvdn { derivatives: n })
        .collect();
    let rows = robustness_table(&specs, &mode, 0.05).unwrap();
    assert_eq!(rows.len(), 4);
    for (n, row) in rows.iter().enumerate() {
        let expected = 4.0 / PI * 0.05_f64.powf(1.0 / (n as f64 + 1.0)).asin();
        close(row.insensitivity, expected, 1e-8, "I(5 %) of ZV-Dⁿ");
        close(
            row.duration_periods,
            (n as f64 + 1.0) / 2.0,
            1e-12,
            "duration",
        );
        assert_eq!(row.impulses, n + 2);
        assert_eq!(row.spec, specs[n]);
        assert_eq!(row.title, "ZV-Dⁿ");
        close(row.duration_s, row.duration_periods / 4.0, 1e-15, "seconds");
    }
    assert!((rows[0].insensitivity - 0.06).abs() < 0.005, "ZV, Fig. 7");
    assert!((rows[1].insensitivity - 0.286).abs() < 0.002, "ZVD, Fig. 7");
    // The damping band of ZV at ζ_m = 0 matches the closed form; ZVD's is where ZV's V² = Vtol.
    let zv_high = root(|z| zv_damping_mismatch(0.0, z) - 0.05, 0.0, 0.2);
    close(
        rows[0].damping_insensitivity,
        zv_high,
        1e-9,
        "ZV damping band",
    );
    let zvd_high = root(|z| zv_damping_mismatch(0.0, z).powi(2) - 0.05, 0.0, 0.3);
    close(
        rows[1].damping_insensitivity,
        zvd_high,
        1e-9,
        "ZVD damping band",
    );
    // Longer zero-derivative shapers are more robust in damping too.
    for w in rows.windows(2) {
        assert!(w[1].damping_insensitivity > w[0].damping_insensitivity);
    }
}

/// The default table lists every family that needs no parameters, in `FAMILIES` order, and
/// leaves out those that do (`zvdn` needs `derivatives`).
#[wasm_bindgen_test(unsupported = test)]
fn parameterless_specs_follow_the_family_table() {
    let specs = parameterless_specs();
    let names: Vec<&str> = specs.iter().map(ShaperSpec::name).collect();
    for family in FAMILIES.iter().filter(|f| f.parameters.is_empty()) {
        assert!(
            names.contains(&family.name),
            "{} missing: {names:?}",
            family.name
        );
    }
    assert!(!names.contains(&"zvdn"), "{names:?}");
    let order: Vec<&str> = FAMILIES
        .iter()
        .map(|f| f.name)
        .filter(|n| names.contains(n))
        .collect();
    assert_eq!(names, order);
    // The list is written out; it must be what parsing `{ family }` for every row of the
    // family table gives (defaults included), less `si`, which parses but needs a band.
    let parsed: Vec<ShaperSpec> = FAMILIES
        .iter()
        .filter_map(|f| serde_json::from_value(serde_json::json!({ "family": f.name })).ok())
        .filter(|spec| !matches!(spec, ShaperSpec::Si(_)))
        .collect();
    assert_eq!(specs, parsed);
    let mode = Mode::new(2.0, 0.05).unwrap();
    let rows = robustness_table(&specs, &mode, 0.05).unwrap();
    assert_eq!(rows.len(), specs.len());
    for row in &rows {
        assert!(
            row.insensitivity > 0.0 && row.damping_insensitivity > 0.0,
            "{row:?}"
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn robustness_table_rejects_bad_input_naming_the_field() {
    let mode = Mode::new(2.0, 0.0).unwrap();
    let err = robustness_table(&[ShaperSpec::Zv], &mode, 1.5).unwrap_err();
    assert_eq!(err.field(), Some("vtol"), "{err}");
    let err = robustness_table(&[ShaperSpec::Zv], &mode, f64::NAN).unwrap_err();
    assert_eq!(err.field(), Some("vtol"), "{err}");
    let err = robustness_table(
        &[ShaperSpec::Zv, ShaperSpec::Zvdn { derivatives: 99 }],
        &mode,
        0.05,
    )
    .unwrap_err();
    assert_eq!(err.field(), Some("specs[1].derivatives"), "{err}");
    let many = vec![ShaperSpec::Zv; MAX_TABLE_ROWS + 1];
    assert!(matches!(
        robustness_table(&many, &mode, 0.05),
        Err(Error::TooLarge { .. })
    ));
    assert_eq!(robustness_table(&[], &mode, 0.05).unwrap(), vec![]);
}

#[wasm_bindgen_test(unsupported = test)]
fn map_rejects_bad_options_naming_the_field() {
    let s = Shaper::identity();
    let ok = map_options(0.0, 10.0, 400, 0.0, 0.3, 200);
    assert!(sensitivity_map(&s, &ok).is_ok());
    let cases = [
        (
            SensitivityMapOptions {
                from_hz: -1.0,
                ..ok
            },
            "fromHz",
        ),
        (SensitivityMapOptions { to_hz: 0.0, ..ok }, "toHz"),
        (
            SensitivityMapOptions {
                to_hz: f64::NAN,
                ..ok
            },
            "toHz",
        ),
        (
            SensitivityMapOptions {
                frequency_points: 1,
                ..ok
            },
            "frequencyPoints",
        ),
        (
            SensitivityMapOptions {
                frequency_points: 2001,
                ..ok
            },
            "frequencyPoints",
        ),
        (
            SensitivityMapOptions {
                damping_points: 1,
                ..ok
            },
            "dampingPoints",
        ),
        (
            SensitivityMapOptions {
                damping_points: usize::MAX,
                ..ok
            },
            "dampingPoints",
        ),
        (
            SensitivityMapOptions {
                damping_from: -0.1,
                ..ok
            },
            "dampingFrom",
        ),
        (
            SensitivityMapOptions {
                damping_to: 1.0,
                ..ok
            },
            "dampingTo",
        ),
        (
            SensitivityMapOptions {
                damping_to: 0.0,
                ..ok
            },
            "dampingTo",
        ),
        (
            SensitivityMapOptions {
                frequency_points: 1000,
                damping_points: 1001,
                ..ok
            },
            "frequencyPoints × dampingPoints",
        ),
    ];
    for (options, field) in cases {
        let err = sensitivity_map(&s, &options).unwrap_err();
        assert_eq!(err.field(), Some(field), "{err}");
        assert!(err.to_string().starts_with(field), "{err}");
    }
    for options in [
        SensitivityMapOptions {
            frequency_points: 2001,
            ..ok
        },
        SensitivityMapOptions {
            frequency_points: 1000,
            damping_points: 1001,
            ..ok
        },
    ] {
        assert!(matches!(
            sensitivity_map(&s, &options),
            Err(Error::TooLarge { .. })
        ));
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn damping_curve_and_band_reject_bad_input_naming_the_field() {
    let s = Shaper::identity();
    let ok = DampingSensitivityOptions {
        frequency_hz: 1.0,
        from_damping: 0.0,
        to_damping: 0.5,
        points: 10,
    };
    let cases = [
        (
            DampingSensitivityOptions {
                frequency_hz: 0.0,
                ..ok
            },
            "frequencyHz",
        ),
        (
            DampingSensitivityOptions {
                frequency_hz: f64::INFINITY,
                ..ok
            },
            "frequencyHz",
        ),
        (
            DampingSensitivityOptions {
                from_damping: f64::NAN,
                ..ok
            },
            "fromDamping",
        ),
        (
            DampingSensitivityOptions {
                to_damping: 1.0,
                ..ok
            },
            "toDamping",
        ),
        (
            DampingSensitivityOptions {
                to_damping: 0.0,
                ..ok
            },
            "toDamping",
        ),
        (DampingSensitivityOptions { points: 1, ..ok }, "points"),
        (
            DampingSensitivityOptions {
                points: usize::MAX,
                ..ok
            },
            "points",
        ),
    ];
    for (options, field) in cases {
        let err = damping_sensitivity(&s, &options).unwrap_err();
        assert_eq!(err.field(), Some(field), "{err}");
    }
    let mode = Mode::new(1.0, 0.0).unwrap();
    for vtol in [0.0, 1.0, f64::NAN] {
        let err = damping_insensitivity(&s, &mode, vtol).unwrap_err();
        assert_eq!(err.field(), Some("vtol"), "{err}");
    }
}

/// The unshaped command leaves V = 1 everywhere (Singhose 2009 eq. 11 normalisation), so the
/// whole map of the identity shaper is 1, and its damping band is empty.
#[wasm_bindgen_test(unsupported = test)]
fn identity_map_is_one_everywhere() {
    let map = sensitivity_map(
        &Shaper::identity(),
        &map_options(0.0, 100.0, 300, 0.0, 0.99, 7),
    )
    .unwrap();
    for v in &map.vibration {
        close(*v, 1.0, 1e-15, "identity");
    }
    let band =
        damping_insensitivity(&Shaper::identity(), &Mode::new(1.0, 0.1).unwrap(), 0.5).unwrap();
    assert_eq!(band.width, 0.0);
}

/// The ZV-Dⁿ damping band grows with n and contains the modelled damping (each ZV-Dⁿ is ZV
/// convolved n+1 times, so its V(ζ) is ZV's to the power n+1).
#[wasm_bindgen_test(unsupported = test)]
fn damping_band_contains_the_model_and_grows_with_derivatives() {
    let mode = Mode::new(3.0, 0.15).unwrap();
    let mut last = 0.0;
    for n in 0..4 {
        let s = zv_dn(&mode, n).unwrap();
        let band = damping_insensitivity(&s, &mode, 0.05).unwrap();
        assert!(
            band.low_damping < 0.15 && band.high_damping > 0.15,
            "{band:?}"
        );
        assert!(band.width > last, "{band:?}");
        last = band.width;
        for edge in [band.low_damping, band.high_damping] {
            let v = zv_damping_mismatch(0.15, edge).powi(n as i32 + 1);
            if edge == 0.0 || edge == MAX_BAND_DAMPING {
                // The band reaches the end of the searched axis, where V is still tolerable.
                assert!(v <= 0.05, "V(0) = {v}");
            } else {
                close(v, 0.05, 1e-8, "V at the band edge");
            }
        }
    }
}
