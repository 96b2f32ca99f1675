//! Specified-insensitivity (SI) shapers (`family: "si"`) against the literature, closed forms
//! and an independent evaluation of V (superposition of impulse responses in time).
//! Two modes of constraint: "sampled" (V ≤ Vtol only at listed frequencies, as the papers do)
//! and "whole band" (the default: V ≤ Vtol everywhere on the band, verified densely).
//! Runs natively (`cargo test`) and in wasm (`wasm-pack test`).

mod common;

use common::{close, residual_by_superposition};
use input_shaping::design::direct::DirectSpec;
use input_shaping::design::specified::SiSpec;
use input_shaping::vibration::residual_vibration;
use input_shaping::{design, DesignRequest, Error, Impulse, Mode, ModeSpec, Shaper};
use std::f64::consts::PI;
use wasm_bindgen_test::wasm_bindgen_test;

fn mode(frequency_hz: f64, damping: f64) -> Vec<ModeSpec> {
    vec![ModeSpec {
        frequency_hz,
        damping,
    }]
}

fn si(spec: SiSpec, f: f64, z: f64) -> Shaper {
    design(&spec.request(mode(f, z))).unwrap()
}

/// V by superposition at frequency `f` and damping `z`.
fn v(s: &Shaper, f: f64, z: f64) -> f64 {
    residual_by_superposition(s, &Mode::new(f, z).unwrap())
}

/// Largest V by superposition over `n` evenly spaced frequencies of [lo, hi] at damping `z`.
fn max_v(s: &Shaper, lo: f64, hi: f64, z: f64, n: usize) -> f64 {
    (0..n)
        .map(|i| v(s, lo + (hi - lo) * i as f64 / (n - 1) as f64, z))
        .fold(0.0, f64::max)
}

/// Peláez & Singhose 2002's example: 0.5 Hz, ζ = 0.002, Vtol = 5 %, I = 0.7, so the band is
/// [0.325, 0.675] Hz.
const PAPER_F: f64 = 0.5;
const PAPER_Z: f64 = 0.002;
/// Their eq. 7.
const PAPER_T: [f64; 4] = [0.0, 0.9767, 1.9383, 2.9151];
const PAPER_A: [f64; 4] = [0.156, 0.344, 0.344, 0.156];

/// The paper samples "six versions of (6) at some specified frequencies (see Fig. 6)"; the
/// figure, and so the frequencies, are not in the text we have. We take six evenly spaced over
/// the band, edges included, as Singhose 2009 Fig. 8 draws them (a reconstruction).
fn paper_samples() -> Vec<f64> {
    (0..6).map(|i| 0.325 + 0.07 * i as f64).collect()
}

/// SAMPLED mode reproduces Peláez & Singhose 2002 eq. 7: four symmetric-looking impulses about
/// 0.97 s apart. Agreement is to ~1 % of the duration: the paper's shaper is not itself a
/// minimum of any sampling that includes its band edges (it leaves 7.4 % at 0.325 Hz, see the
/// next test), so it cannot be matched exactly. The duration also matches an independent
/// design of the same sampled problem, scipy SLSQP from random starts (benches/si_slsqp.py:
/// 2.895073 s, t = [0, 0.96332, 1.93253, 2.89507], A = [0.16417, 0.3381, 0.33631, 0.16142]).
#[wasm_bindgen_test(unsupported = test)]
fn pelaez_singhose_2002_eq7_sampled_mode() {
    let s = si(
        SiSpec {
            insensitivity: Some(0.7),
            sample_frequencies_hz: Some(paper_samples()),
            ..Default::default()
        },
        PAPER_F,
        PAPER_Z,
    );
    assert_eq!(s.len(), 4);
    for (imp, (t, a)) in s.impulses().iter().zip(PAPER_T.iter().zip(PAPER_A)) {
        close(imp.time, *t, 0.025, "time vs eq. 7");
        close(imp.amplitude, a, 0.01, "amplitude vs eq. 7");
    }
    close(s.duration(), 2.895073, 2e-6, "duration vs SLSQP");
    let slsqp = [
        (0.0, 0.16417),
        (0.96332, 0.3381),
        (1.93253, 0.33631),
        (2.89507, 0.16142),
    ];
    for (imp, (t, a)) in s.impulses().iter().zip(slsqp) {
        close(imp.time, t, 1e-5, "time vs SLSQP");
        close(imp.amplitude, a, 1e-5, "amplitude vs SLSQP");
    }
    for f in paper_samples() {
        assert!(v(&s, f, PAPER_Z) <= 0.05 * (1.0 + 1e-9), "V({f} Hz)");
    }
    // Sampled means sampled: between the samples V exceeds 5 %.
    assert!(max_v(&s, 0.325, 0.675, PAPER_Z, 2000) > 0.05);
}

/// The paper's own shaper (eq. 7) leaves 7.4 % at the band's lower edge, 0.325 Hz, and 5.46 %
/// at 0.60 Hz — it does not hold Vtol = 5 % over I = 0.7.
#[wasm_bindgen_test(unsupported = test)]
fn pelaez_singhose_2002_eq7_exceeds_vtol_on_its_band() {
    let paper = Shaper::new(
        PAPER_T
            .iter()
            .zip(PAPER_A)
            .map(|(&time, amplitude)| Impulse { time, amplitude })
            .collect(),
    )
    .unwrap();
    close(v(&paper, 0.325, PAPER_Z), 0.074, 5e-4, "V(0.325 Hz)");
    close(
        residual_vibration(&paper, &Mode::new(0.325, PAPER_Z).unwrap()),
        v(&paper, 0.325, PAPER_Z),
        1e-12,
        "eq. 11 vs superposition",
    );
    close(v(&paper, 0.6, PAPER_Z), 0.0546, 5e-4, "V(0.6 Hz)");
}

/// WHOLE-BAND mode (default) for the same request: V ≤ 5 % everywhere on [0.325, 0.675] Hz
/// (checked here by superposition on 4001 frequencies), slightly longer than both the sampled
/// design and the paper's shaper (which does not hold the bound).
#[wasm_bindgen_test(unsupported = test)]
fn pelaez_singhose_2002_whole_band_mode_holds_everywhere() {
    let whole = si(
        SiSpec {
            insensitivity: Some(0.7),
            ..Default::default()
        },
        PAPER_F,
        PAPER_Z,
    );
    assert!(max_v(&whole, 0.325, 0.675, PAPER_Z, 4001) <= 0.05 * (1.0 + 1e-9));
    assert!(whole.duration() > 2.895073 && whole.duration() > PAPER_T[3]);
    assert!(whole.duration() < PAPER_T[3] * 1.02, "{}", whole.duration());
    // Touches the bound: it is as short as it can be for this band.
    assert!(max_v(&whole, 0.325, 0.675, PAPER_Z, 4001) > 0.0499);
    close(whole.amplitude_sum(), 1.0, 1e-12, "Σ A");
    assert!(whole.impulses().iter().all(|i| i.amplitude >= 0.0));
}

/// Singhose 2009 Fig. 11: EI shapers are nodes of the SI curve. At ζ = 0 the EI shaper
/// [(1+V)/4, (1−V)/2, (1+V)/4] at [0, T/2, T] has V(f) = |(1−V)/2 + (1+V)/2·cos(πf/f_m)|, so
/// its 5 % band edges solve cos(πr) = (3V−1)/(1+V): I = 2(1 − acos((3V−1)/(1+V))/π) = 0.3995
/// ("0.4" in Fig. 7). SI with exactly that insensitivity is the EI shaper, one period long;
/// with I = 0.4 it is a hair longer (about one period).
#[wasm_bindgen_test(unsupported = test)]
fn si_at_ei_insensitivity_is_the_ei_shaper() {
    let vtol: f64 = 0.05;
    let i_ei = 2.0 * (1.0 - ((3.0 * vtol - 1.0) / (1.0 + vtol)).acos() / PI);
    close(i_ei, 0.3995, 1e-4, "EI insensitivity");
    let s = si(
        SiSpec {
            insensitivity: Some(i_ei),
            ..Default::default()
        },
        1.0,
        0.0,
    );
    let want = [
        (0.0, (1.0 + vtol) / 4.0),
        (0.5, (1.0 - vtol) / 2.0),
        (1.0, (1.0 + vtol) / 4.0),
    ];
    assert_eq!(s.len(), 3);
    for (imp, (t, a)) in s.impulses().iter().zip(want) {
        close(imp.time, t, 1e-7, "EI time");
        close(imp.amplitude, a, 1e-7, "EI amplitude");
    }
    let s = si(
        SiSpec {
            insensitivity: Some(0.4),
            ..Default::default()
        },
        1.0,
        0.0,
    );
    assert!(
        (1.0..1.01).contains(&s.duration()),
        "I = 0.4: {} periods",
        s.duration()
    );
    assert!(max_v(&s, 0.8, 1.2, 0.0, 2001) <= vtol * (1.0 + 1e-9));
}

/// Singhose 2009 Fig. 9 and 11: more insensitivity costs duration, monotonically; every design
/// holds V ≤ Vtol over its band (superposition, 2001 frequencies).
#[wasm_bindgen_test(unsupported = test)]
fn longer_for_wider_bands() {
    let mut last = 0.0;
    for i in [0.1, 0.3, 0.5, 0.7, 0.9] {
        let s = si(
            SiSpec {
                insensitivity: Some(i),
                ..Default::default()
            },
            2.0,
            0.03,
        );
        let (lo, hi) = (2.0 * (1.0 - i / 2.0), 2.0 * (1.0 + i / 2.0));
        assert!(
            max_v(&s, lo, hi, 0.03, 2001) <= 0.05 * (1.0 + 1e-9),
            "I = {i}"
        );
        assert!(s.duration() > last, "I = {i}");
        last = s.duration();
    }
}

/// `si` over modes at `freqs` (each at damping `zeta`), insensitivity `i`, Vtol `vtol`.
fn si_over(freqs: &[f64], zeta: f64, i: f64, vtol: f64) -> Shaper {
    let modes = freqs
        .iter()
        .map(|&frequency_hz| ModeSpec {
            frequency_hz,
            damping: zeta,
        })
        .collect();
    let spec = SiSpec {
        vtol,
        insensitivity: Some(i),
        ..SiSpec::default()
    };
    design(&spec.request(modes)).unwrap()
}

/// A positive shaper with Σ A = 1 and V ≤ `vtol` (by superposition, 1001 points) over every
/// band f(1 ± i/2) of `freqs` at damping `zeta`.
fn assert_holds_on_bands(s: &Shaper, freqs: &[f64], zeta: f64, i: f64, vtol: f64) {
    close(s.amplitude_sum(), 1.0, 1e-12, "Σ A");
    assert!(s.impulses().iter().all(|p| p.amplitude > 0.0));
    for &f in freqs {
        let (lo, hi) = (f * (1.0 - i / 2.0), f * (1.0 + i / 2.0));
        let worst = max_v(s, lo, hi, zeta, 1001);
        assert!(worst <= vtol * (1.0 + 1e-9), "V = {worst} on {lo}…{hi} Hz");
    }
}

/// Four modes (1.2 / 3.4 / 7.9 / 13 Hz, ζ 0.02), each over f(1 ± 0.15) at Vtol 5 %: the polish
/// converges to a few impulses. Until its trial points were pulled back onto the constraints
/// by chords while they contract (12 at most) rather than by 4, every null-space step it
/// tried was refused and the design fell back to the grid: 257 impulses, 0.949509329311 s
/// (natively, release, 2026-12-07). Checked here independently: V by superposition on a dense
/// grid over every band, Σ A = 1, positive amplitudes, and no longer than that fallback.
#[wasm_bindgen_test(unsupported = test)]
fn four_mode_si_polishes_to_a_few_impulses() {
    let freqs = [1.2, 3.4, 7.9, 13.0];
    let s = si_over(&freqs, 0.02, 0.3, 0.05);
    assert!(s.len() <= 20, "{} impulses", s.len());
    assert_holds_on_bands(&s, &freqs, 0.02, 0.3, 0.05);
    assert!(s.duration() <= 0.949_509_329_311, "{} s", s.duration());
}

/// Three modes 1 / 3 / 7 Hz (ζ 0.02, I 0.5, Vtol 5 %): the polish converges from the grid
/// solution's clusters (13 impulses, 1.347063739314 s) and from the start with its widest
/// cluster split (14 impulses, 1.347056823402 s; natively, release, 2026-12-07). The shorter
/// must be kept: returning the first start that converges gave the 13-impulse one, 5 ppm
/// longer than before issue 24's polish work, whose line search failed on that start. Checked
/// independently: V by superposition over every band, Σ A = 1, positive amplitudes.
#[wasm_bindgen_test(unsupported = test)]
fn the_shortest_polished_start_is_kept() {
    let freqs = [1.0, 3.0, 7.0];
    let s = si_over(&freqs, 0.02, 0.5, 0.05);
    assert!(
        s.duration() <= 1.347_056_83,
        "{} s, {} impulses",
        s.duration(),
        s.len()
    );
    assert_holds_on_bands(&s, &freqs, 0.02, 0.5, 0.05);
}

/// One mode at 1 Hz, ζ 0.1, over f(1 ± 0.55) at Vtol 2 % (a point of the convergence grid):
/// the grid solution's unused points are small, not 0, and no start from its clusters counted
/// from 1e-6 of the largest amplitude polished: the design fell back to the grid, 101
/// impulses, 2.609761976 s (natively, 2026-12-07). The clusters with that noise taken for zero
/// polish it to 7 impulses (issue 24). Checked independently: V by superposition over the
/// band, Σ A = 1, positive amplitudes, and no longer than that fallback.
#[wasm_bindgen_test(unsupported = test)]
fn a_grid_solution_with_noise_between_impulses_polishes() {
    let s = si_over(&[1.0], 0.1, 1.1, 0.02);
    assert!(s.len() <= 10, "{} impulses", s.len());
    assert_holds_on_bands(&s, &[1.0], 0.1, 1.1, 0.02);
    assert!(
        s.duration() <= 2.609_761_976 * (1.0 + 1e-9),
        "{} s",
        s.duration()
    );
}

/// Singhose 2009 Fig. 10: robust over 0.7 … 1.3 Hz *and* ζ ∈ [0, 0.2]. V ≤ 5 % on a dense
/// (f, ζ) grid, and the damping range costs duration over the same band at one damping.
#[wasm_bindgen_test(unsupported = test)]
fn frequency_and_damping_range_fig10() {
    let s = si(
        SiSpec {
            band_hz: Some([0.7, 1.3]),
            damping_range: Some([0.0, 0.2]),
            ..Default::default()
        },
        1.0,
        0.1,
    );
    for j in 0..=20 {
        let z = 0.2 * j as f64 / 20.0;
        assert!(
            max_v(&s, 0.7, 1.3, z, 601) <= 0.05 * (1.0 + 1e-9),
            "ζ = {z}"
        );
    }
    let single = si(
        SiSpec {
            band_hz: Some([0.7, 1.3]),
            ..Default::default()
        },
        1.0,
        0.1,
    );
    assert!(s.duration() > single.duration());
}

/// Weighted design (`vtolProfile`): Vtol 2 % at the band's low end rising to 8 % at its top
/// (Singhose 2009 §3.1: weight the lower frequencies more). V ≤ Vtol(f) everywhere, and the
/// result differs from the constant-Vtol design.
#[wasm_bindgen_test(unsupported = test)]
fn weighted_vtol_profile() {
    let profile = vec![[0.65, 0.02], [1.35, 0.08]];
    let vtol_at = |f: f64| 0.02 + 0.06 * (f - 0.65) / 0.7;
    let s = si(
        SiSpec {
            insensitivity: Some(0.7),
            vtol_profile: Some(profile),
            ..Default::default()
        },
        1.0,
        0.0,
    );
    for k in 0..=2000 {
        let f = 0.65 + 0.7 * k as f64 / 2000.0;
        assert!(v(&s, f, 0.0) <= vtol_at(f) * (1.0 + 1e-9), "V({f} Hz)");
    }
    let flat = si(
        SiSpec {
            insensitivity: Some(0.7),
            ..Default::default()
        },
        1.0,
        0.0,
    );
    assert!((s.duration() - flat.duration()).abs() > 1e-3);
    // Tighter where the weight is, looser at the top: the low end is held below 5 %.
    assert!(max_v(&s, 0.65, 0.75, 0.0, 201) < 0.05);
}

/// Negative amplitudes allowed (amplitudeMin = −0.2): V ≤ Vtol still holds on the band, every
/// impulse respects its bounds, and the shaper is shorter than the positive one.
#[wasm_bindgen_test(unsupported = test)]
fn negative_amplitudes_give_a_shorter_si() {
    let spec = |amplitude_min: f64| SiSpec {
        insensitivity: Some(0.5),
        amplitude_min,
        ..Default::default()
    };
    let positive = si(spec(0.0), 1.0, 0.0);
    let negative = si(spec(-0.2), 1.0, 0.0);
    assert!(negative.duration() < positive.duration());
    assert!(negative.impulses().iter().any(|i| i.amplitude < 0.0));
    assert!(negative
        .impulses()
        .iter()
        .all(|i| (-0.2 - 1e-9..=1.0 + 1e-9).contains(&i.amplitude)));
    close(negative.amplitude_sum(), 1.0, 1e-9, "Σ A");
    assert!(max_v(&negative, 0.75, 1.25, 0.0, 2001) <= 0.05 * (1.0 + 1e-9));
}

/// An amplitudeMax far above anything a shaper summing to 1 can reach binds nothing: the same
/// shaper as a bound just above that reach, every amplitude within amplitudeMin, Σ A = 1. Found
/// by the 10⁶-case property run (2026-12-06): with `amplitudeMax: 1e12` the design program's
/// scale was the bound's, its Σ A came out 4e-5 short, and the rescaled amplitudes fell 6e-7
/// below amplitudeMin, which a bound tolerance taken relative to the 10¹² range let through.
#[wasm_bindgen_test(unsupported = test)]
fn a_huge_amplitude_max_binds_nothing() {
    let amplitude_min = -0.10950142210936772;
    let spec = |amplitude_max: f64| SiSpec {
        vtol: 0.01,
        insensitivity: Some(0.8024150574274576),
        amplitude_min,
        amplitude_max,
        ..Default::default()
    };
    let huge = si(spec(1e12), 0.05, 0.0);
    let reach = si(spec(30.0), 0.05, 0.0);
    assert!(huge
        .impulses()
        .iter()
        .all(|i| i.amplitude >= amplitude_min - 1e-12));
    close(huge.amplitude_sum(), 1.0, 1e-12, "Σ A");
    close(huge.duration(), reach.duration(), 1e-9, "duration");
    assert_eq!(huge.len(), reach.len());
}

/// Several modes: a band around each, designed together.
#[wasm_bindgen_test(unsupported = test)]
fn two_modes_two_bands() {
    let modes = vec![
        ModeSpec {
            frequency_hz: 1.0,
            damping: 0.02,
        },
        ModeSpec {
            frequency_hz: 3.3,
            damping: 0.01,
        },
    ];
    let s = design(
        &SiSpec {
            insensitivity: Some(0.3),
            ..Default::default()
        }
        .request(modes),
    )
    .unwrap();
    assert!(max_v(&s, 0.85, 1.15, 0.02, 1001) <= 0.05 * (1.0 + 1e-9));
    assert!(max_v(&s, 3.3 * 0.85, 3.3 * 1.15, 0.01, 1001) <= 0.05 * (1.0 + 1e-9));
}

/// Infeasible requests say why: too few impulses allowed, or too short a duration.
#[wasm_bindgen_test(unsupported = test)]
fn infeasible_requests_say_why() {
    let base = SiSpec {
        insensitivity: Some(0.7),
        ..Default::default()
    };
    let err = design(
        &SiSpec {
            max_impulses: Some(3),
            ..base.clone()
        }
        .request(mode(0.5, 0.002)),
    )
    .unwrap_err();
    match err {
        Error::Infeasible { reason } => {
            assert!(reason.contains("maxImpulses = 3"), "{reason}");
            assert!(reason.contains("4 impulses"), "{reason}");
        }
        e => panic!("expected Infeasible, got {e}"),
    }
    // The sampled design needs 2.895 s, the whole band 2.94 s: 2.5 s is not enough.
    let err = design(
        &SiSpec {
            max_duration: Some(2.5),
            ..base
        }
        .request(mode(0.5, 0.002)),
    )
    .unwrap_err();
    match err {
        Error::Infeasible { reason } => assert!(reason.contains("maxDuration"), "{reason}"),
        e => panic!("expected Infeasible, got {e}"),
    }
}

/// Bad parameters are errors naming the field as a JS user writes it.
#[wasm_bindgen_test(unsupported = test)]
fn bad_parameters_name_their_field() {
    let cases: Vec<(SiSpec, &str)> = vec![
        (SiSpec::default(), "insensitivity"),
        (
            SiSpec {
                insensitivity: Some(0.5),
                band_hz: Some([0.8, 1.2]),
                ..Default::default()
            },
            "bandHz",
        ),
        (
            SiSpec {
                insensitivity: Some(-0.5),
                ..Default::default()
            },
            "insensitivity",
        ),
        (
            SiSpec {
                insensitivity: Some(2.5),
                ..Default::default()
            },
            "insensitivity",
        ),
        (
            SiSpec {
                band_hz: Some([1.2, 0.8]),
                ..Default::default()
            },
            "bandHz",
        ),
        (
            SiSpec {
                band_hz: Some([0.0, 0.8]),
                ..Default::default()
            },
            "bandHz[0]",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                vtol: 1.5,
                ..Default::default()
            },
            "vtol",
        ),
        // subnormal: no finite reciprocal (the solver never returned, 2026-12-06)
        (
            SiSpec {
                insensitivity: Some(0.5),
                vtol: 1e-310,
                ..Default::default()
            },
            "vtol",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                vtol_profile: Some(vec![[1.0, 0.05], [2.0, 1e-310]]),
                ..Default::default()
            },
            "vtolProfile[1][1]",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                vtol: f64::NAN,
                ..Default::default()
            },
            "vtol",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                damping_range: Some([0.1, 1.0]),
                ..Default::default()
            },
            "dampingRange[1]",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                sample_frequencies_hz: Some(vec![0.9, 2.0]),
                ..Default::default()
            },
            "sampleFrequenciesHz[1]",
        ),
        (
            SiSpec {
                sample_frequencies_hz: Some(vec![]),
                ..Default::default()
            },
            "sampleFrequenciesHz",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                vtol_profile: Some(vec![[1.0, 0.05], [0.9, 0.05]]),
                ..Default::default()
            },
            "vtolProfile[1][0]",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                vtol_profile: Some(vec![[1.0, 0.0]]),
                ..Default::default()
            },
            "vtolProfile[0][1]",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                amplitude_min: 2.0,
                ..Default::default()
            },
            "amplitudeMin",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                max_impulses: Some(0),
                ..Default::default()
            },
            "maxImpulses",
        ),
        (
            SiSpec {
                insensitivity: Some(0.5),
                max_duration: Some(-1.0),
                ..Default::default()
            },
            "maxDuration",
        ),
    ];
    for (spec, field) in cases {
        let err = design(&spec.clone().request(mode(1.0, 0.0))).unwrap_err();
        assert_eq!(err.field(), Some(field), "{spec:?}: {err}");
    }
    // A subnormal Vtol is shown as it was given, with the reason.
    let tiny = SiSpec {
        insensitivity: Some(0.5),
        vtol: 1e-310,
        ..Default::default()
    };
    let err = design(&tiny.request(mode(1.0, 0.0)))
        .unwrap_err()
        .to_string();
    assert!(err.contains("got 1e-310 (a subnormal number"), "{err}");
    // bandHz is one band: not with several modes.
    let two = vec![
        ModeSpec {
            frequency_hz: 1.0,
            damping: 0.0,
        },
        ModeSpec {
            frequency_hz: 2.0,
            damping: 0.0,
        },
    ];
    let err = design(
        &SiSpec {
            band_hz: Some([0.8, 1.2]),
            ..Default::default()
        }
        .request(two),
    )
    .unwrap_err();
    assert_eq!(err.field(), Some("bandHz"));
}

/// The spec parses from JSON as a user writes it (camelCase), and the family is in the table.
#[wasm_bindgen_test(unsupported = test)]
fn si_spec_from_json() {
    let request: DesignRequest = serde_json::from_str(
        r#"{ "family": "si", "modes": [{ "frequencyHz": 0.5, "damping": 0.002 }],
             "vtol": 0.05, "insensitivity": 0.7,
             "sampleFrequenciesHz": [0.325, 0.395, 0.465, 0.535, 0.605, 0.675] }"#,
    )
    .unwrap();
    assert_eq!(request.shaper.name(), "si");
    let info = request.shaper.info().unwrap();
    assert!(info.parameters.contains(&"sampleFrequenciesHz"));
    close(
        design(&request).unwrap().duration(),
        2.895073,
        2e-6,
        "duration",
    );
    let parsed: DesignRequest = serde_json::from_str(
        r#"{ "family": "si", "modes": [{ "frequencyHz": 1 }], "bandHz": [0.7, 1.3],
             "dampingRange": [0, 0.2], "vtolProfile": [[0.7, 0.03], [1.3, 0.06]],
             "amplitudeMin": -0.1, "amplitudeMax": 1.2, "maxImpulses": 9, "maxDuration": 4 }"#,
    )
    .unwrap();
    match parsed.shaper {
        input_shaping::ShaperSpec::Si(spec) => {
            assert_eq!(spec.band_hz, Some([0.7, 1.3]));
            assert_eq!(spec.damping_range, Some([0.0, 0.2]));
            assert_eq!(spec.max_impulses, Some(9));
            assert_eq!(spec.amplitude_min, -0.1);
        }
        other => panic!("parsed as {other:?}"),
    }
}

/// The full convergence grid's one real defect (issue 6): SI for four modes (1, 1.1, 3, 10 Hz)
/// at ζ = 0 and I = 0.9, Vtol 5 %, once returned amplitudes summing to 1 + 1.8·10⁻⁸. Its
/// results come from the solver's fallback (the polish fails), solved to the duration search's
/// tolerance 10⁻⁷ and, with no zero constraints, not projected: Σ A = 1 − 5·10⁻⁹ and
/// 1 − 5·10⁻⁸ in two exchange rounds, the second with an amplitude of −2·10⁻⁶ (refused since
/// the bounds check of e273eab). Now every result is renormalised to Σ A = 1 before it is
/// checked, so no shaper with Σ A ≠ 1 can come back: this point must give Σ A = 1 to rounding,
/// amplitudes within the bounds and V ≤ Vtol on every band. Until 2026-12-07 it gave a typed
/// `infeasible` error (the −2·10⁻⁶ amplitude) after ≈ 5 min at `--profile bench`, and the test
/// was ignored as slow; since the polish's trial points are restored by chords while they
/// contract (issue 24), the polish converges: 33 impulses, 2.111382 s, in 4.3 s at
/// `--profile bench` and 4.5 s at the test profile. So it runs with the others now and asks
/// for the shaper, with few impulses (the grid fallback's would number hundreds).
#[test]
#[cfg(not(target_arch = "wasm32"))]
fn four_modes_amplitudes_sum_to_one() {
    let (vtol, i) = (0.05, 0.9);
    let freqs = [1.0, 1.1, 3.0, 10.0];
    let s = si_over(&freqs, 0.0, i, vtol);
    assert!(s.len() <= 40, "{} impulses: not polished", s.len());
    let sum: f64 = s.impulses().iter().map(|p| p.amplitude).sum();
    assert!((sum - 1.0).abs() <= 1e-12, "Σ A = {sum}");
    for p in s.impulses() {
        assert!(
            (0.0..=1.0 + 1e-12).contains(&p.amplitude),
            "amplitude {}",
            p.amplitude
        );
    }
    for &f in &freqs {
        let (lo, hi) = (f * (1.0 - i / 2.0), f * (1.0 + i / 2.0));
        let worst = max_v(&s, lo, hi, 0.0, 2001);
        assert!(worst <= vtol * (1.0 + 1e-6), "V = {worst} on {lo}…{hi} Hz");
    }
}

/// A request of the 10⁶-case property run (`any_request_is_ok_and_valid_or_a_typed_error`,
/// `PROPTEST_RNG_SEED=7`, 2026-12-06) on which `design` never returned: `si` over a band with
/// a Vtol profile down to 2.2·10⁻³⁰⁸ (the smallest normal number, so not refused as subnormal)
/// for a 30 Hz, ζ 0.37 mode. The polish met a Jacobian with a NaN, and nalgebra's `svd` never
/// returns on one (a CPU profile of the stuck run: all of it in `SVD::new`); the
/// decompositions are bounded since c6c37ec. It ends now, in a shaper that holds or an error.
#[wasm_bindgen_test(unsupported = test)]
fn a_vtol_profile_down_to_the_smallest_normal_number_ends() {
    let spec = SiSpec {
        vtol: -0.0,
        band_hz: Some([0.7623072833017429, 1.642451375970284]),
        vtol_profile: Some(vec![
            [8.125437352970569e-285, 0.03810334979549615],
            [1.5186110467120582, 2.2250738585072014e-308],
            [1.8888378672601878, 0.07280723242393498],
        ]),
        amplitude_min: 0.0,
        amplitude_max: 1.0,
        max_impulses: Some(6),
        ..Default::default()
    };
    let result = design(&spec.request(mode(30.084678125565432, 0.36871695620597994)));
    // Vtol ≈ 0 over an interval around 1.52 Hz: no shaper of 6 positive impulses holds it.
    assert!(
        matches!(result, Err(Error::Infeasible { .. })),
        "{result:?}"
    );
}

/// Issue 24's six-mode `si` (1.2 / 3.4 / 7.9 / 13 / 21 / 34 Hz, ζ 0.02, I 0.3, Vtol 5 %, the
/// README's example): until 2026-12-07 every round's polish failed and, after about a minute
/// natively, "the vibration bound could not be met everywhere on the band after 8 rounds". The
/// polish's second start (clusters with the grid solution's noise taken for zero) gives a
/// design in the last of the 8 exchange rounds (so one round less would lose it): 29
/// impulses, 0.953096 s, in 43 s natively at release. Slow, so ignored; run by
/// `npm run test:long`. Checked independently: V by superposition over every band, Σ A = 1,
/// positive amplitudes, and a few impulses (a grid fallback would number hundreds).
#[test]
#[cfg(not(target_arch = "wasm32"))]
#[ignore = "long: about a minute; run with --ignored (npm run test:long)"]
fn six_mode_si_is_designed() {
    let freqs = [1.2, 3.4, 7.9, 13.0, 21.0, 34.0];
    let s = si_over(&freqs, 0.02, 0.3, 0.05);
    assert!(s.len() <= 40, "{} impulses", s.len());
    assert_holds_on_bands(&s, &freqs, 0.02, 0.3, 0.05);
}

/// `design_report` says how the solver reached an `si` or `direct` design, and nothing for a
/// closed-form family: polished (exact, few impulses) for one mode at I 0.5; a grid solution
/// (`polished: false`, its many impulses) for 1 and 3 Hz at I 0.5, ζ 0.02, Vtol 5 %, a point of
/// the convergence grid that still falls back (docs/benchmarks.md, 122 impulses; when the
/// solver learns to polish it, another fallback point of the grid takes its place here).
#[wasm_bindgen_test(unsupported = test)]
fn the_design_report_says_whether_the_polish_converged() {
    let modes = |freqs: &[f64]| -> Vec<ModeSpec> {
        freqs
            .iter()
            .map(|&frequency_hz| ModeSpec {
                frequency_hz,
                damping: 0.02,
            })
            .collect()
    };
    let si = |i: f64| SiSpec {
        insensitivity: Some(i),
        ..SiSpec::default()
    };
    let one = input_shaping::design::design_report(&si(0.5).request(modes(&[1.0]))).unwrap();
    let report = one.solver.expect("si reports");
    assert!(
        report.polished && report.rounds >= 1 && report.programs >= 1,
        "{report:?}"
    );
    assert!(one.shaper.len() <= 6, "{} impulses", one.shaper.len());
    let two = input_shaping::design::design_report(&si(0.5).request(modes(&[1.0, 3.0]))).unwrap();
    let report = two.solver.expect("si reports");
    assert!(
        !report.polished,
        "{report:?}, {} impulses",
        two.shaper.len()
    );
    assert!(two.shaper.len() > 30, "{} impulses", two.shaper.len());
    assert_holds_on_bands(&two.shaper, &[1.0, 3.0], 0.02, 0.5, 0.05);
    let direct =
        input_shaping::design::design_report(&DirectSpec::default().request(modes(&[1.2, 3.4])))
            .unwrap();
    assert!(
        direct.solver.is_some_and(|r| r.polished),
        "{:?}",
        direct.solver
    );
    let zvd = input_shaping::design::design_report(&DesignRequest {
        modes: modes(&[1.0]),
        shaper: input_shaping::ShaperSpec::Zvd,
    })
    .unwrap();
    assert!(zvd.solver.is_none());
}
