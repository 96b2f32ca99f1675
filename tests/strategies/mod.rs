//! proptest strategies shared by the property tests (issue 6): numbers that include every
//! awkward f64 (NaN, ±∞, ±0, subnormals, huge, negative) alongside realistic ones, and every
//! spec the public API takes, built field by field from them.
#![allow(dead_code)]

use input_shaping::command::{CommandSpec, Interpolation};
use input_shaping::design::direct::DirectSpec;
use input_shaping::design::quantize::{QuantizeMethod, QuantizeOptions};
use input_shaping::design::sampled::{Objective, SampledSpec};
use input_shaping::design::specified::SiSpec;
use input_shaping::plant::{PendulumSpec, PlantModeSpec, PlantSpec, TwoMass};
use input_shaping::profile::ProfileSpec;
use input_shaping::{DesignRequest, Impulse, ModeSpec, ShaperSpec};
use proptest::prelude::*;
use proptest::test_runner::Config;

/// The test's default case count, unless `PROPTEST_CASES` is set (then that, for every test:
/// the long profile is `PROPTEST_CASES=1000000`).
pub fn config(default_cases: u32) -> Config {
    let mut c = Config::default();
    if std::env::var("PROPTEST_CASES").is_err() {
        c.cases = default_cases;
    }
    // Shrinking a slow design case can take long; a few hundred steps are plenty.
    c.max_shrink_iters = 512;
    // A fixed seed unless PROPTEST_RNG_SEED is set: `npm test` (and CI) run the same cases on
    // every machine, so a red run is reproducible; the long profile and fuzzing explore.
    if std::env::var("PROPTEST_RNG_SEED").is_err() {
        c.rng_seed = proptest::test_runner::RngSeed::Fixed(0x1a2b_3c4d);
    }
    c
}

/// Values at the edges of f64 and of the library's domains.
pub const SPECIAL: &[f64] = &[
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    f64::MIN_POSITIVE,
    5e-324,
    -5e-324,
    1e-310,
    f64::MAX,
    f64::MIN,
    f64::EPSILON,
    1e-300,
    1e300,
    1e-9,
    1e9,
    1e-12,
    1e12,
    1.0,
    -1.0,
    0.5,
    2.0,
    0.999_999_999_999,
    1.0 - f64::EPSILON,
    1.0 + f64::EPSILON,
    0.001,
    0.3,
];

/// A number from `realistic` most of the time, else a special value, a negative of the range,
/// or any bit pattern at all (every class: NaN, ∞, subnormal, normal, zero).
pub fn num(realistic: std::ops::Range<f64>) -> BoxedStrategy<f64> {
    let lo = realistic.start;
    let hi = realistic.end;
    prop_oneof![
        16 => realistic,
        2 => prop::sample::select(SPECIAL),
        1 => (lo..hi).prop_map(|x| -x),
        1 => any::<f64>(),
    ]
    .boxed()
}

/// `value` most of the time (a default the family accepts), else `other`.
pub fn mostly<T: std::fmt::Debug + Clone + 'static>(
    value: T,
    other: BoxedStrategy<T>,
) -> BoxedStrategy<T> {
    prop_oneof![4 => Just(value), 1 => other].boxed()
}

/// `None` most of the time, else `Some` of `s`.
pub fn rarely<S: Strategy + 'static>(s: S) -> BoxedStrategy<Option<S::Value>>
where
    S::Value: Clone,
{
    prop::option::weighted(0.2, s).boxed()
}

/// A count: usually small, sometimes at or past the library's limits.
pub fn count(realistic: std::ops::Range<usize>) -> BoxedStrategy<usize> {
    prop_oneof![
        8 => realistic,
        1 => prop::sample::select(vec![0usize, 1, 2, 255, 256, 257, 100_001, 1_000_001, usize::MAX]),
        1 => any::<usize>(),
    ]
    .boxed()
}

/// A u32 parameter: usually in `realistic`, sometimes anything.
pub fn small_u32(realistic: std::ops::Range<u32>) -> BoxedStrategy<u32> {
    prop_oneof![9 => realistic, 1 => any::<u32>()].boxed()
}

pub fn mode_spec() -> BoxedStrategy<ModeSpec> {
    (num(0.05..50.0), num(0.0..0.4))
        .prop_map(|(frequency_hz, damping)| ModeSpec {
            frequency_hz,
            damping,
        })
        .boxed()
}

/// 0 … `max` modes (0 is an error the API must report), one most often.
pub fn modes(max: usize) -> BoxedStrategy<Vec<ModeSpec>> {
    prop_oneof![
        1 => prop::collection::vec(mode_spec(), 0..=max),
        2 => prop::collection::vec(mode_spec(), 1..=1),
    ]
    .boxed()
}

pub fn impulse() -> BoxedStrategy<Impulse> {
    (num(0.0..5.0), num(-1.0..1.5))
        .prop_map(|(time, amplitude)| Impulse { time, amplitude })
        .boxed()
}

pub fn impulses(max: usize) -> BoxedStrategy<Vec<Impulse>> {
    prop::collection::vec(impulse(), 0..=max).boxed()
}

fn opt<S: Strategy + 'static>(s: S) -> BoxedStrategy<Option<S::Value>> {
    prop::option::of(s).boxed()
}

pub fn vtol() -> BoxedStrategy<f64> {
    num(0.001..0.5)
}

pub fn sampled_spec() -> BoxedStrategy<SampledSpec> {
    (
        (num(0.005..0.05), count(8..40), opt(small_u32(0..8))),
        (
            mostly(0.1, num(0.0..10.0)),
            small_u32(0..4),
            rarely(num(1e-4..1.0)),
        ),
        prop::sample::select(vec![Objective::ControlError, Objective::MinimumNorm]),
        (
            rarely(num(-0.5..0.2)),
            rarely(num(0.2..1.5)),
            rarely(num(-0.5..0.0)),
            rarely(num(0.0..0.5)),
        ),
    )
        .prop_map(
            |(
                (period_s, impulses, delay_samples),
                (weight, derivatives, plant_gain),
                objective,
                b,
            )| {
                SampledSpec {
                    period_s,
                    impulses,
                    delay_samples,
                    weight,
                    derivatives,
                    plant_gain,
                    objective,
                    amplitude_min: b.0,
                    amplitude_max: b.1,
                    increment_min: b.2,
                    increment_max: b.3,
                }
            },
        )
        .boxed()
}

/// SI parameters. Bands are kept moderate most of the time so a case takes milliseconds.
pub fn si_spec() -> BoxedStrategy<SiSpec> {
    // Which band: insensitivity (0), bandHz (1), sampled frequencies only (2), or any mix.
    (
        (
            num(0.01..0.2),
            prop_oneof![4 => 0..3u8, 1 => 3..4u8],
            num(0.05..1.0),
            (num(0.5..1.0), num(1.0..2.0)),
        ),
        (
            rarely((num(0.0..0.1), num(0.0..0.2))),
            prop::collection::vec(num(0.5..2.0), 0..8),
            rarely(prop::collection::vec((num(0.5..2.0), vtol()), 0..4)),
        ),
        (
            mostly(0.0, num(-0.3..0.0)),
            mostly(1.0, num(0.5..1.5)),
            rarely(count(1..12)),
            rarely(num(0.5..20.0)),
        ),
    )
        .prop_map(
            |((vtol, kind, i, band), (damping_range, samples, profile), (amin, amax, n, d))| {
                let insensitivity = (kind == 0 || kind == 3).then_some(i);
                let band = (kind == 1 || kind == 3).then_some(band);
                let samples = (kind == 2 || kind == 3).then_some(samples);
                SiSpec {
                    vtol,
                    insensitivity,
                    band_hz: band.map(|(a, b)| [a, b]),
                    damping_range: damping_range.map(|(a, b)| [a, a + b]),
                    sample_frequencies_hz: samples,
                    vtol_profile: profile.map(|p| {
                        let mut p: Vec<[f64; 2]> = p.into_iter().map(|(f, v)| [f, v]).collect();
                        p.sort_by(|a, b| a[0].total_cmp(&b[0]));
                        p
                    }),
                    amplitude_min: amin,
                    amplitude_max: amax,
                    max_impulses: n,
                    max_duration: d,
                }
            },
        )
        .boxed()
}

pub fn direct_spec() -> BoxedStrategy<DirectSpec> {
    (
        small_u32(0..4),
        mostly(0.0, num(-0.3..0.0)),
        mostly(1.0, num(0.5..1.5)),
        rarely(num(0.5..20.0)),
    )
        .prop_map(
            |(derivatives, amplitude_min, amplitude_max, max_duration)| DirectSpec {
                derivatives,
                amplitude_min,
                amplitude_max,
                max_duration,
            },
        )
        .boxed()
}

/// Every family, with arbitrary parameters.
pub fn shaper_spec() -> BoxedStrategy<ShaperSpec> {
    prop_oneof![
        Just(ShaperSpec::Zv),
        Just(ShaperSpec::Zvd),
        Just(ShaperSpec::Zvdd),
        small_u32(0..35).prop_map(|derivatives| ShaperSpec::Zvdn { derivatives }),
        sampled_spec().prop_map(ShaperSpec::Sampled),
        vtol().prop_map(|vtol| ShaperSpec::Ei { vtol }),
        vtol().prop_map(|vtol| ShaperSpec::Ei2 { vtol }),
        vtol().prop_map(|vtol| ShaperSpec::Ei3 { vtol }),
        (small_u32(0..12), vtol()).prop_map(|(humps, vtol)| ShaperSpec::Eihump { humps, vtol }),
        Just(ShaperSpec::Mzv),
        Just(ShaperSpec::Umzv),
        Just(ShaperSpec::Umzvd),
        vtol().prop_map(|vtol| ShaperSpec::Umei { vtol }),
        (num(0.01..10.0), num(0.1..100.0)).prop_map(|(distance, max_acceleration)| {
            ShaperSpec::Bangbang {
                distance,
                max_acceleration,
            }
        }),
        (num(0.01..10.0), num(0.1..100.0), num(0.0..5.0)).prop_map(
            |(distance, max_acceleration, coast_time)| ShaperSpec::Onoff {
                distance,
                max_acceleration,
                coast_time,
            }
        ),
        (impulses(12), any::<bool>()).prop_map(|(impulses, normalize)| ShaperSpec::Custom {
            impulses,
            normalize
        }),
        si_spec().prop_map(ShaperSpec::Si),
        direct_spec().prop_map(ShaperSpec::Direct),
    ]
    .boxed()
}

/// The families cheap enough to design thousands of times (no convex program).
pub fn cheap_shaper_spec() -> BoxedStrategy<ShaperSpec> {
    prop_oneof![
        Just(ShaperSpec::Zv),
        Just(ShaperSpec::Zvd),
        Just(ShaperSpec::Zvdd),
        small_u32(0..35).prop_map(|derivatives| ShaperSpec::Zvdn { derivatives }),
        vtol().prop_map(|vtol| ShaperSpec::Ei { vtol }),
        vtol().prop_map(|vtol| ShaperSpec::Ei2 { vtol }),
        Just(ShaperSpec::Mzv),
        Just(ShaperSpec::Umzv),
        vtol().prop_map(|vtol| ShaperSpec::Umei { vtol }),
        (impulses(8), any::<bool>()).prop_map(|(impulses, normalize)| ShaperSpec::Custom {
            impulses,
            normalize
        }),
    ]
    .boxed()
}

pub fn request(max_modes: usize) -> BoxedStrategy<DesignRequest> {
    (modes(max_modes), shaper_spec())
        .prop_map(|(modes, shaper)| DesignRequest { modes, shaper })
        .boxed()
}

pub fn quantize_options() -> BoxedStrategy<QuantizeOptions> {
    (
        small_u32(1..70_000),
        opt(num(1e-5..1e-2)),
        prop::sample::select(vec![
            QuantizeMethod::LargestRemainder,
            QuantizeMethod::UpdateTime,
        ]),
        opt(num(0.1..10.0)),
        vtol(),
    )
        .prop_map(
            |(amplitude_steps, tick_s, method, ramp_s, vtol)| QuantizeOptions {
                amplitude_steps,
                tick_s,
                method,
                ramp_s,
                vtol,
            },
        )
        .boxed()
}

pub fn profile_spec() -> BoxedStrategy<ProfileSpec> {
    prop_oneof![
        (num(0.2..10.0), num(-2.0..2.0), num(0.5..5.0)).prop_map(|(f, d, t)| ProfileSpec::Pulse {
            frequency_hz: f,
            distance: d,
            duration: t
        }),
        (num(0.2..10.0), num(-2.0..2.0), num(0.5..5.0)).prop_map(|(f, d, t)| {
            ProfileSpec::Triangle {
                frequency_hz: f,
                distance: d,
                duration: t,
            }
        }),
        (num(0.2..10.0), num(0.0..1.0), num(-2.0..2.0), num(0.5..5.0)).prop_map(|(f, df, d, t)| {
            ProfileSpec::RobustTrapezium {
                frequency_hz: f,
                delta_hz: df,
                distance: d,
                duration: t,
            }
        }),
        (
            prop::collection::vec(num(0.2..10.0), 0..4),
            opt(num(0.2..5.0)),
            num(-2.0..2.0),
            num(0.5..5.0)
        )
            .prop_map(
                |(modes_hz, common_hz, distance, duration)| ProfileSpec::MultiMode {
                    modes_hz,
                    common_hz,
                    distance,
                    duration,
                }
            ),
    ]
    .boxed()
}

pub fn command_spec() -> BoxedStrategy<CommandSpec> {
    prop_oneof![
        (num(-2.0..2.0), num(0.0..1.0))
            .prop_map(|(distance, start)| CommandSpec::Step { distance, start }),
        (num(-2.0..2.0), num(0.0..1.0))
            .prop_map(|(slope, start)| CommandSpec::Ramp { slope, start }),
        (num(-2.0..2.0), num(0.1..5.0), num(0.5..20.0), num(0.0..1.0)).prop_map(
            |(distance, max_velocity, max_acceleration, start)| CommandSpec::Trapezoid {
                distance,
                max_velocity,
                max_acceleration,
                start,
            }
        ),
        (
            num(-2.0..2.0),
            num(0.1..5.0),
            num(0.5..20.0),
            num(1.0..200.0),
            num(0.0..1.0)
        )
            .prop_map(
                |(distance, max_velocity, max_acceleration, max_jerk, start)| {
                    CommandSpec::SCurve {
                        distance,
                        max_velocity,
                        max_acceleration,
                        max_jerk,
                        start,
                    }
                }
            ),
        (
            num(1e-3..0.05),
            prop::collection::vec(num(-2.0..2.0), 0..200),
            prop::sample::select(vec![Interpolation::Linear, Interpolation::Hold])
        )
            .prop_map(
                |(sample_period, values, interpolation)| CommandSpec::Sampled {
                    sample_period,
                    values,
                    interpolation,
                }
            ),
        profile_spec().prop_map(CommandSpec::Profile),
    ]
    .boxed()
}

pub fn plant_spec() -> BoxedStrategy<PlantSpec> {
    prop_oneof![
        prop::collection::vec((num(0.1..10.0), num(0.0..0.3), opt(num(0.0..1.0))), 0..4).prop_map(
            |m| PlantSpec::Modal {
                modes: m
                    .into_iter()
                    .map(|(frequency_hz, damping, participation)| PlantModeSpec {
                        frequency_hz,
                        damping,
                        participation,
                    })
                    .collect()
            }
        ),
        Just(PlantSpec::VecianaTestBed),
        (
            num(0.1..10.0),
            num(0.1..10.0),
            num(1.0..1000.0),
            num(0.0..5.0)
        )
            .prop_map(|(base_mass, tip_mass, stiffness, damping_coefficient)| {
                PlantSpec::TwoMass(TwoMass {
                    base_mass,
                    tip_mass,
                    stiffness,
                    damping_coefficient,
                })
            }),
        (
            num(0.2..5.0),
            num(5.0..15.0),
            num(0.0..0.2),
            num(-1.0..1.0),
            opt(prop_oneof![
                (num(-0.5..0.5), num(0.1..2.0), num(0.5..5.0), num(0.0..1.0)).prop_map(
                    |(distance, max_velocity, max_acceleration, start)| CommandSpec::Trapezoid {
                        distance,
                        max_velocity,
                        max_acceleration,
                        start,
                    }
                ),
                (num(-0.5..0.5), num(0.0..1.0))
                    .prop_map(|(distance, start)| CommandSpec::Step { distance, start }),
            ]
            .boxed())
        )
            .prop_map(|(length, gravity, damping, initial_angle, hoist)| {
                PlantSpec::Pendulum(PendulumSpec {
                    length,
                    gravity,
                    damping,
                    initial_angle,
                    hoist,
                })
            }),
    ]
    .boxed()
}
