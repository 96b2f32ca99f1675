//! Convolved shapers kept factored (`Shaper::convolve_factored`, and `Shaper::convolve` past
//! `MAX_IMPULSES`): every analysis computed from the factors against the same analysis of the
//! expanded shaper where expansion is possible (≤ 4096 impulses), V against the closed form
//! (the product of the factors' V), and issue 24's six modes with ZV-D³ (5⁶ = 15 625
//! impulses), which `design` refused before. Then the faster paths against the ones they
//! replace: I(Vtol)'s bounded scan against the full scan (bit for bit) and the joint scan
//! against each mode's own (1e-12 × f), a command shaped by merging sorted runs against the
//! sorted products (bit for bit), and the `factors` of a factored shaper's wire form.

mod common;

use common::Rng;
use input_shaping::command::{Command, CommandSpec};
use input_shaping::design::design_for;
use input_shaping::design::zero_vibration::zv_dn;
use input_shaping::plant::{ModalPlant, Plant};
use input_shaping::shaper::{MAX_CONVOLVED_IMPULSES, MAX_IMPULSES};
use input_shaping::simulate::simulate_shaped;
use input_shaping::vibration::{
    damping_sensitivity, insensitivities, insensitivity, insensitivity_full_scan,
    residual_vibration, sensitivity, vibration_rad, DampingSensitivityOptions, Insensitivity,
    SensitivityOptions,
};
use input_shaping::{Impulse, Mode, Shaper, ShaperSpec};

fn six_modes() -> Vec<Mode> {
    [1.2, 3.4, 7.9, 13.0, 21.0, 34.0]
        .iter()
        .map(|&f| Mode::new(f, 0.02).unwrap())
        .collect()
}

/// Relative difference, scaled by at least 1.
fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1.0)
}

/// A random single-mode factor: ZV-Dⁿ (n 0 … 3) at a random mode, or random custom impulses
/// (negative amplitudes too).
fn random_factor(rng: &mut Rng) -> Shaper {
    if rng.uniform() < 0.6 {
        let mode = Mode::new(0.5 + 40.0 * rng.uniform(), 0.3 * rng.uniform().powi(2)).unwrap();
        zv_dn(&mode, (4.0 * rng.uniform()) as u32).unwrap()
    } else {
        let n = 2 + (4.0 * rng.uniform()) as usize;
        Shaper::new(
            (0..n)
                .map(|_| Impulse {
                    time: 0.5 * rng.uniform(),
                    amplitude: rng.uniform() - 0.3,
                })
                .collect(),
        )
        .unwrap()
    }
}

/// The pair (expanded, factored) of the same random convolution of 2 … 4 factors, ≤ 4096
/// impulses.
fn random_pair(rng: &mut Rng) -> (Shaper, Shaper) {
    let k = 2 + (3.0 * rng.uniform()) as usize;
    let factors: Vec<Shaper> = (0..k).map(|_| random_factor(rng)).collect();
    let mut expanded = factors[0].clone();
    let mut factored = factors[0].clone();
    for f in &factors[1..] {
        expanded = expanded.convolve(f).unwrap();
        factored = factored.convolve_factored(f).unwrap();
    }
    assert!(!expanded.is_factored() && factored.is_factored());
    (expanded, factored)
}

#[test]
fn factored_analyses_equal_the_expanded_ones() {
    let mut rng = Rng(24);
    for _ in 0..40 {
        let (e, f) = random_pair(&mut rng);
        // Formed lazily, the impulses are the expanded shaper's.
        assert_eq!(e.len(), f.len());
        for (a, b) in e.impulses().iter().zip(f.impulses()) {
            assert!(rel(a.time, b.time) < 1e-12 && rel(a.amplitude, b.amplitude) < 1e-12);
        }
        assert!(rel(f.duration(), e.duration()) < 1e-12);
        assert!(rel(f.amplitude_sum(), e.amplitude_sum()) < 1e-12);
        match (f.centroid_delay(), e.centroid_delay()) {
            (Some(a), Some(b)) => assert!(rel(a, b) < 1e-9, "{a} vs {b}"),
            (a, b) => assert_eq!(a.is_some(), b.is_some()),
        }
        let top = 3.0 / f.duration().max(1e-3) + 20.0;
        let options = SensitivityOptions {
            from_hz: 0.0,
            to_hz: top,
            points: 400,
            damping: 0.05,
        };
        let (ce, cf) = (
            sensitivity(&e, &options).unwrap(),
            sensitivity(&f, &options).unwrap(),
        );
        let scale = e.impulses().iter().map(|i| i.amplitude.abs()).sum::<f64>();
        for (a, b) in ce.vibration.iter().zip(&cf.vibration) {
            assert!((a - b).abs() < 1e-12 * scale.max(1.0), "V(f): {a} vs {b}");
        }
        let d = DampingSensitivityOptions {
            frequency_hz: 0.3 * top,
            from_damping: 0.0,
            to_damping: 0.5,
            points: 50,
        };
        let (de, df) = (
            damping_sensitivity(&e, &d).unwrap(),
            damping_sensitivity(&f, &d).unwrap(),
        );
        for (a, b) in de.vibration.iter().zip(&df.vibration) {
            assert!((a - b).abs() < 1e-12 * scale.max(1.0), "V(ζ): {a} vs {b}");
        }
    }
}

#[test]
fn factored_multi_mode_designs_keep_bands_and_responses() {
    // Where the design still expands (≤ 4096), the same design kept factored has the same
    // I(Vtol) bands and the same simulated response.
    let modes = six_modes();
    let plant = Plant::Modal(
        ModalPlant::new(
            modes
                .iter()
                .map(|m| Mode::new(m.frequency_hz() * 1.05, 0.03).unwrap())
                .collect(),
            vec![1.0 / 6.0; 6],
        )
        .unwrap(),
    );
    let command = Command::from_spec(&CommandSpec::Trapezoid {
        distance: 1.0,
        max_velocity: 0.75,
        max_acceleration: 8.0,
        start: 0.0,
    })
    .unwrap();
    for (n, spec) in [(2, ShaperSpec::Zv), (3, ShaperSpec::Zvd)] {
        let singles: Vec<Shaper> = modes.iter().map(|m| zv_dn(m, n - 2).unwrap()).collect();
        let e = design_for(&spec, &modes).unwrap();
        let f = singles[1..]
            .iter()
            .try_fold(singles[0].clone(), |a, s| a.convolve_factored(s))
            .unwrap();
        assert!(f.is_factored() && !e.is_factored());
        assert_eq!(f.factor_impulses(), n as usize * 6);
        for m in &modes {
            for vtol in [0.05, 0.1] {
                let (be, bf) = (
                    insensitivity(&e, m, vtol).unwrap(),
                    insensitivity(&f, m, vtol).unwrap(),
                );
                // The scan's step depends on the work it counts (fewer terms factored: a
                // finer or equal step), so an edge agrees to the refinement's tolerance.
                assert!(
                    (be.low_hz - bf.low_hz).abs() < 1e-6 * m.frequency_hz()
                        && (be.high_hz - bf.high_hz).abs() < 1e-6 * m.frequency_hz(),
                    "{spec:?} at {} Hz: {be:?} vs {bf:?}",
                    m.frequency_hz()
                );
            }
        }
        let (te, tf) = (
            simulate_shaped(&plant, &command, &e, 2e-3, 3.0).unwrap(),
            simulate_shaped(&plant, &command, &f, 2e-3, 3.0).unwrap(),
        );
        for (a, b) in te.endpoint.iter().zip(&tf.endpoint) {
            assert!((a - b).abs() < 1e-10, "{a} vs {b}");
        }
    }
}

#[test]
fn six_modes_zv_d3_is_designed_factored() {
    // 5⁶ = 15 625 impulses: over MAX_IMPULSES, under MAX_CONVOLVED_IMPULSES.
    let modes = six_modes();
    let shaper = design_for(&ShaperSpec::Zvdn { derivatives: 3 }, &modes).unwrap();
    assert!(shaper.is_factored());
    assert_eq!(shaper.factor_impulses(), 5 * 6);
    let singles: Vec<Shaper> = modes.iter().map(|m| zv_dn(m, 3).unwrap()).collect();
    // Closed forms: the duration is the sum of the factors' durations (ZV-D³: 2 damped
    // periods each), the amplitude sum the product (1), V the product of the factors' V.
    let periods: f64 = modes.iter().map(|m| 2.0 * m.damped_period_s()).sum();
    assert!(rel(shaper.duration(), periods) < 1e-12);
    assert!(rel(shaper.amplitude_sum(), 1.0) < 1e-12);
    for m in &modes {
        assert!(residual_vibration(&shaper, m) < 1e-9);
    }
    let options = SensitivityOptions {
        from_hz: 0.0,
        to_hz: 60.0,
        points: 301,
        damping: 0.02,
    };
    let curve = sensitivity(&shaper, &options).unwrap();
    for (f, v) in curve.frequency_hz.iter().zip(&curve.vibration) {
        let w = 2.0 * std::f64::consts::PI * f;
        let product: f64 = singles
            .iter()
            .map(|s| vibration_rad(s.impulses(), w, 0.02))
            .product();
        assert!((v - product).abs() < 1e-12, "at {f} Hz: {v} vs {product}");
    }
    // Expanded lazily, once: the impulses' own V is the product to rounding.
    let impulses = shaper.impulses();
    assert!(impulses.len() > MAX_IMPULSES && impulses.len() <= MAX_CONVOLVED_IMPULSES);
    assert!(rel(impulses.last().unwrap().time, periods) < 1e-12);
    for f in [0.7, 2.0, 5.5, 10.0, 17.0, 27.0, 45.0] {
        let w = 2.0 * std::f64::consts::PI * f;
        let product: f64 = singles
            .iter()
            .map(|s| vibration_rad(s.impulses(), w, 0.02))
            .product();
        assert!((vibration_rad(impulses, w, 0.02) - product).abs() < 1e-9);
    }
    // Every band is found, from the factors.
    for m in &modes {
        let band = insensitivity(&shaper, m, 0.05).unwrap();
        assert!(band.low_hz < m.frequency_hz() && m.frequency_hz() < band.high_hz);
    }
}

#[test]
fn a_convolution_past_the_factored_limit_is_refused() {
    let modes: Vec<Mode> = (0..7)
        .map(|k| Mode::new(1.0 + 3.0 * k as f64, 0.02).unwrap())
        .collect();
    // 5⁷ = 78 125 > MAX_CONVOLVED_IMPULSES.
    let e = design_for(&ShaperSpec::Zvdn { derivatives: 3 }, &modes).unwrap_err();
    assert_eq!(e.field(), Some("impulses"));
}

/// Shapers and mode sets the band scans are compared on: the page's four closed-form families
/// over issue 24's six modes and over three modes, at damping 0, 0.02 and mixed, and random
/// convolutions (negative amplitudes too) at random modes.
fn band_cases() -> Vec<(String, Shaper, Vec<Mode>)> {
    let mut cases = Vec::new();
    let three = [(1.2, 0.012), (3.4, 0.013), (7.9, 0.02)];
    let six = [1.2, 3.4, 7.9, 13.0, 21.0, 34.0];
    let sets: Vec<(&str, Vec<Mode>)> = vec![
        ("six ζ 0.02", six_modes()),
        (
            "six ζ 0",
            six.iter().map(|&f| Mode::new(f, 0.0).unwrap()).collect(),
        ),
        (
            "six ζ 0.1 / 0.02",
            six.iter()
                .enumerate()
                .map(|(k, &f)| Mode::new(f, if k % 2 == 0 { 0.1 } else { 0.02 }).unwrap())
                .collect(),
        ),
        (
            "three",
            three
                .iter()
                .map(|&(f, z)| Mode::new(f, z).unwrap())
                .collect(),
        ),
    ];
    for (name, modes) in sets {
        for (family, spec) in [
            ("ZV", ShaperSpec::Zv),
            ("ZVD", ShaperSpec::Zvd),
            ("ZVDD", ShaperSpec::Zvdd),
            ("ZV-D3", ShaperSpec::Zvdn { derivatives: 3 }),
            ("EI", ShaperSpec::Ei { vtol: 0.05 }),
        ] {
            if let Ok(shaper) = design_for(&spec, &modes) {
                cases.push((format!("{family}, {name}"), shaper, modes.clone()));
            }
        }
    }
    let mut rng = Rng(0x2424_2424_2424_2424);
    for k in 0..30 {
        let (_, shaper) = random_pair(&mut rng);
        let zeta = if k % 3 == 0 { 0.0 } else { 0.2 * rng.uniform() };
        let modes = (0..3)
            .map(|_| Mode::new(0.5 + 40.0 * rng.uniform(), zeta).unwrap())
            .collect();
        cases.push((format!("random {k}"), shaper, modes));
    }
    cases
}

#[test]
fn the_bounded_band_scan_is_the_full_scan_bit_for_bit() {
    // The decay bound only ends an upper scan where the full scan finds nothing either: the
    // same edges to the last bit (the full scan is the path before the bound).
    let mut stopped_early = 0;
    for (name, shaper, modes) in band_cases() {
        for m in &modes {
            for vtol in [0.05, 0.2] {
                let full = insensitivity_full_scan(&shaper, m, vtol).unwrap();
                let bounded = insensitivity(&shaper, m, vtol).unwrap();
                assert_eq!(
                    bounded,
                    full,
                    "{name} at {} Hz, Vtol {vtol}",
                    m.frequency_hz()
                );
                if full.high_hz == 50.0 * m.frequency_hz() && m.damping() > 0.0 {
                    stopped_early += 1;
                }
            }
        }
    }
    // The cases hold bands that reach the 50 × f limit with damping (where the bound can end
    // the scan): the comparison is not vacuous.
    assert!(stopped_early >= 10, "{stopped_early} bands to the limit");
}

/// Whether two bands agree: each edge to 1e-12 of the mode's frequency.
fn same_band(a: &Insensitivity, b: &Insensitivity, f: f64) -> bool {
    (a.low_hz - b.low_hz).abs() <= 1e-12 * f
        && (a.high_hz - b.high_hz).abs() <= 1e-12 * f
        && (a.width - b.width).abs() <= 1e-12
}

#[test]
fn bands_scanned_jointly_are_each_modes_own() {
    // insensitivities shares a band between the modes inside it (same damping); each must be
    // the band insensitivity finds from that mode alone. Issue 24's six modes share one band for
    // modes 2 … 6 (ZVD and longer at ζ 0.02), so the sharing is exercised.
    let mut shared = 0;
    for (name, shaper, modes) in band_cases() {
        for vtol in [0.05, 0.2] {
            let joint = insensitivities(&shaper, &modes, vtol).unwrap();
            assert_eq!(joint.len(), modes.len());
            for (m, j) in modes.iter().zip(&joint) {
                let own = insensitivity(&shaper, m, vtol).unwrap();
                let f = m.frequency_hz();
                assert!(
                    same_band(j, &own, f),
                    "{name} at {f} Hz, Vtol {vtol}: {j:?} vs {own:?}"
                );
            }
            shared += joint
                .iter()
                .zip(&modes)
                .filter(|(b, m)| {
                    modes.iter().any(|o| {
                        o.frequency_hz() != m.frequency_hz()
                            && b.low_hz < o.frequency_hz()
                            && o.frequency_hz() < b.high_hz
                    })
                })
                .count();
        }
    }
    assert!(shared >= 20, "{shared} bands holding another mode");
}

#[test]
fn the_wire_form_of_a_factored_shaper_carries_its_factors() {
    // `factors` is written only for a factored shaper: the per-mode ZV-D³ shapers, whose
    // convolution is `impulses`; read back, it is ignored.
    let modes = six_modes();
    let shaper = design_for(&ShaperSpec::Zvdn { derivatives: 3 }, &modes).unwrap();
    let json = serde_json::to_value(shaper.to_data()).unwrap();
    let factors: Vec<Vec<Impulse>> = serde_json::from_value(json["factors"].clone()).unwrap();
    assert_eq!(factors.len(), 6);
    for (f, m) in factors.iter().zip(&modes) {
        assert_eq!(f, zv_dn(m, 3).unwrap().impulses());
    }
    let convolved = factors[1..]
        .iter()
        .map(|f| Shaper::new(f.clone()).unwrap())
        .try_fold(Shaper::new(factors[0].clone()).unwrap(), |a, f| {
            a.convolve_factored(&f)
        })
        .unwrap();
    let impulses: Vec<Impulse> = serde_json::from_value(json["impulses"].clone()).unwrap();
    assert_eq!(convolved.impulses(), &impulses[..]);
    let back: input_shaping::shaper::ShaperData = serde_json::from_value(json).unwrap();
    assert!(back.factors.is_none() && back.impulses == impulses);
    // A shaper formed from its impulses has none.
    let zvd = design_for(&ShaperSpec::Zvd, &modes[..3]).unwrap();
    assert!(serde_json::to_value(zvd.to_data())
        .unwrap()
        .get("factors")
        .is_none());
}

#[test]
fn a_command_shaped_by_merged_runs_is_the_sorted_one_bit_for_bit() {
    // Piecewise::shaped merges its sorted runs (one per knot of a short command); the path
    // before it built every product and sorted them in Piecewise::new. Same knots, same order
    // of merged ties, so equal to the last bit: trapezoids (also triangular, and starting at
    // 0.3 s), an S-curve, shaped by multi-mode designs (coincident products in the ZVD ⊛ ZVD
    // of one mode twice) and random convolutions with negative amplitudes.
    use input_shaping::command::{s_curve, trapezoid};
    use input_shaping::piecewise::{Knot, Piecewise};
    let commands = [
        trapezoid(1.0, 0.75, 8.0, 0.0).unwrap(),
        trapezoid(0.01, 0.75, 8.0, 0.3).unwrap(),
        trapezoid(-2.0, 1.5, 3.0, 0.0).unwrap(),
        s_curve(1.0, 0.75, 8.0, 200.0, 0.0).unwrap(),
    ];
    let mode = Mode::new(3.0, 0.05).unwrap();
    let zvd = zv_dn(&mode, 1).unwrap();
    let mut shapers = vec![
        zvd.convolve(&zvd).unwrap(),
        design_for(&ShaperSpec::Zvdd, &six_modes()).unwrap(),
        design_for(&ShaperSpec::Zvdn { derivatives: 3 }, &six_modes()[..4]).unwrap(),
    ];
    let mut rng = Rng(77);
    for _ in 0..10 {
        shapers.push(random_pair(&mut rng).1);
    }
    for c in &commands {
        assert!(c.knots().len() <= 16);
        for s in &shapers {
            let mut products = Vec::new();
            for k in c.knots() {
                for imp in s.impulses() {
                    products.push(Knot {
                        time: k.time + imp.time,
                        jumps: k.jumps.map(|j| j * imp.amplitude),
                    });
                }
            }
            let sorted = Piecewise::new(products).unwrap();
            assert_eq!(c.shaped(s).unwrap(), sorted);
        }
    }
}
