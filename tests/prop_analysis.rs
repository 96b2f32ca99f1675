//! Property tests of every public function downstream of a design (issue 6): vibration curves,
//! maps and bands, quantisation, exports, Klipper figures, charts, commands, profiles,
//! simulation, spectra, the robustness table and the solver itself — arbitrary f64s (NaN, ±∞,
//! subnormals, huge, negative) and lengths in, `Ok` with sane numbers or a typed `Error` out,
//! never a panic.
//!
//! Case counts: a short default per test (`npm test`); `PROPTEST_CASES=N` overrides every test.
#![cfg(not(target_arch = "wasm32"))]

mod independent;
mod strategies;

use independent::check_valid;
use input_shaping::chart::{self, ChartStyle};
use input_shaping::command::{self, Command};
use input_shaping::design::{quantize, sampled};
use input_shaping::plant::{two_mass, Plant};
use input_shaping::scenario::{self, SimulationSpec, SpectrumSpec};
use input_shaping::spectrum::SpectrumSignal;
use input_shaping::vibration::*;
use input_shaping::{export, metrics, profile, robustness, smoothing, solve};
use input_shaping::{Error, Mode, Shaper, ShaperSpec};
use plotters::prelude::*;
use proptest::prelude::*;
use strategies::*;

fn check_error(e: &Error) -> Result<(), TestCaseError> {
    prop_assert!(!e.to_string().trim().is_empty(), "empty message for {e:?}");
    Ok(())
}

/// `Ok(x)` runs `check(x)`; `Err` must be readable.
fn ok_or_typed<T>(
    r: input_shaping::Result<T>,
    check: impl FnOnce(T) -> Result<(), TestCaseError>,
) -> Result<(), TestCaseError> {
    match r {
        Ok(x) => check(x),
        Err(e) => check_error(&e),
    }
}

fn all_finite(xs: &[f64]) -> bool {
    xs.iter().all(|x| x.is_finite())
}

/// A valid shaper of up to 30 impulses: arbitrary impulses that the constructor accepts, or
/// (when it refuses them) a ZVD for 1 Hz.
fn shaper() -> BoxedStrategy<Shaper> {
    prop_oneof![
        impulses(30).prop_map(|i| Shaper::new(i).ok()),
        (mode_spec(), cheap_shaper_spec()).prop_map(|(m, s)| {
            input_shaping::design::design(&input_shaping::DesignRequest {
                modes: vec![m],
                shaper: s,
            })
            .ok()
        }),
    ]
    .prop_map(|s| {
        s.unwrap_or_else(|| {
            input_shaping::design::zero_vibration::zvd(&Mode::new(1.0, 0.0).unwrap()).unwrap()
        })
    })
    .boxed()
}

fn points() -> BoxedStrategy<usize> {
    count(0..2000)
}

proptest! {
    #![proptest_config(config(1500))]

    #[test]
    fn vibration_curves_and_bands(
        s in shaper(),
        (from_hz, to_hz, damping) in (num(0.0..5.0), num(0.5..10.0), num(0.0..0.5)),
        n in points(),
        mode in mode_spec(),
        vtol in num(0.001..0.5),
    ) {
        let _ = vibration_rad(s.impulses(), from_hz, damping); // any f64 out, no panic
        ok_or_typed(
            sensitivity(&s, &SensitivityOptions { from_hz, to_hz, points: n, damping }),
            |c| {
                prop_assert_eq!(c.frequency_hz.len(), n);
                prop_assert_eq!(c.vibration.len(), n);
                prop_assert!(all_finite(&c.vibration) && all_finite(&c.frequency_hz));
                prop_assert!(c.vibration.iter().all(|&v| v >= 0.0));
                Ok(())
            },
        )?;
        if let Ok(m) = Mode::from_spec(&mode) {
            let _ = residual_vibration(&s, &m);
            ok_or_typed(insensitivity(&s, &m, vtol), |b| {
                prop_assert!(b.low_hz <= m.frequency_hz() && m.frequency_hz() <= b.high_hz, "{b:?}");
                prop_assert!(b.width >= 0.0 && b.width.is_finite(), "{b:?}");
                Ok(())
            })?;
            ok_or_typed(damping_insensitivity(&s, &m, vtol), |b| {
                prop_assert!(b.low_damping <= m.damping() && m.damping() <= b.high_damping, "{b:?}");
                prop_assert!(b.width >= 0.0 && b.width.is_finite(), "{b:?}");
                Ok(())
            })?;
            ok_or_typed(sampled::ramp_delay(&s, &m), |d| {
                prop_assert!(d.is_finite());
                Ok(())
            })?;
        }
        ok_or_typed(
            damping_sensitivity(
                &s,
                &DampingSensitivityOptions {
                    frequency_hz: to_hz,
                    from_damping: from_hz / 10.0,
                    to_damping: damping,
                    points: n,
                },
            ),
            |c| {
                prop_assert_eq!(c.damping.len(), n);
                prop_assert!(all_finite(&c.vibration));
                Ok(())
            },
        )?;
    }

    #[test]
    fn sensitivity_maps(
        s in shaper(),
        (from_hz, to_hz) in (num(0.0..5.0), num(0.5..10.0)),
        (z0, z1) in (num(0.0..0.3), num(0.1..0.9)),
        (nf, nz) in (count(0..300), count(0..100)),
        vtol in num(0.001..0.5),
    ) {
        let options = SensitivityMapOptions {
            from_hz,
            to_hz,
            frequency_points: nf,
            damping_from: z0,
            damping_to: z1,
            damping_points: nz,
        };
        ok_or_typed(sensitivity_map(&s, &options), |m| {
            prop_assert_eq!(m.vibration.len(), nf * nz);
            prop_assert!(all_finite(&m.vibration));
            let mut svg = String::new();
            {
                let area = SVGBackend::with_string(&mut svg, (320, 200)).into_drawing_area();
                let r = chart::draw_sensitivity_map(&area, &m, Some(vtol), &[(from_hz, z0)], &ChartStyle { scale: vtol * 4.0, ..ChartStyle::default() });
                ok_or_typed(r, |_| Ok(()))?;
            }
            let _ = chart::map::contour_segments(&m, vtol);
            Ok(())
        })?;
    }

    #[test]
    fn quantize_export_and_klipper(
        s in shaper(),
        mode in mode_spec(),
        options in quantize_options(),
        (steps, tick) in (small_u32(1..70_000), num(1e-6..1e-2)),
        (accel, scv) in (num(100.0..20000.0), num(0.0..20.0)),
        name in "[a-z_]{0,8}|\\PC{0,12}",
    ) {
        ok_or_typed(quantize::quantize(&s, &options), |q| {
            check_valid(&q).map_err(TestCaseError::fail)
        })?;
        if let Ok(m) = Mode::from_spec(&mode) {
            ok_or_typed(quantize::quantize_with_report(&s, &m, &options), |r| {
                prop_assert!(r.vibration_after.is_finite() && r.amplitude_sum.is_finite());
                Ok(())
            })?;
        }
        let csv = export::to_csv(&s);
        prop_assert_eq!(csv.lines().count(), s.len() + 1);
        let json = export::to_json(&s);
        prop_assert!(serde_json::from_str::<serde_json::Value>(&json).is_ok(), "{json}");
        ok_or_typed(export::to_c_float(&s, &name, &name), |_| Ok(()))?;
        ok_or_typed(export::to_c_fixed(&s, &name, &name, steps, tick), |_| Ok(()))?;
        ok_or_typed(export::to_rrf_m593(&s), |_| Ok(()))?;
        ok_or_typed(smoothing::smoothing(&s, accel, scv), |x| {
            prop_assert!(!x.is_nan());
            Ok(())
        })?;
        ok_or_typed(smoothing::max_accel(&s, scv), |x| {
            prop_assert!(!x.is_nan());
            Ok(())
        })?;
        ok_or_typed(smoothing::klipper_figures(&s, scv), |_| Ok(()))?;
    }

    #[test]
    fn charts_on_any_input(
        shapers in prop::collection::vec(shaper(), 0..4),
        curve in prop::collection::vec((num(0.0..10.0), num(0.0..1.0)), 0..50),
        vtol in prop::option::of(num(0.001..0.5)),
        modes_hz in prop::collection::vec(num(0.1..10.0), 0..3),
        scale in num(0.5..3.0),
    ) {
        let style = ChartStyle { scale, ..ChartStyle::default() };
        let series: Vec<(&str, &Shaper)> = shapers.iter().map(|s| ("s", s)).collect();
        let c = SensitivityCurve {
            frequency_hz: curve.iter().map(|p| p.0).collect(),
            vibration: curve.iter().map(|p| p.1).collect(),
        };
        let d = DampingSensitivityCurve {
            damping: curve.iter().map(|p| p.0 / 10.0).collect(),
            vibration: curve.iter().map(|p| p.1).collect(),
        };
        let mut svg = String::new();
        {
            let area = SVGBackend::with_string(&mut svg, (320, 200)).into_drawing_area();
            ok_or_typed(chart::draw_impulses(&area, &series, &style), |_| Ok(()))?;
            ok_or_typed(chart::draw_sensitivity(&area, &[("c", &c)], vtol, &modes_hz, &style), |_| Ok(()))?;
            ok_or_typed(chart::draw_damping_sensitivity(&area, &[("d", &d)], vtol, &modes_hz, &style), |_| Ok(()))?;
        }
        for x in modes_hz {
            let _ = chart::map::scale_color(x);
        }
    }
}

proptest! {
    #![proptest_config(config(600))]

    #[test]
    fn commands_and_profiles(
        spec in command_spec(),
        (a, b, c, d) in (num(-2.0..2.0), num(0.1..5.0), num(0.5..20.0), num(1.0..200.0)),
        s in shaper(),
        period in num(1e-3..0.05),
        xs in prop::collection::vec(num(-1.0..1.0), 0..100),
    ) {
        ok_or_typed(command::step(a, b), |_| Ok(()))?;
        ok_or_typed(command::ramp(a, b), |_| Ok(()))?;
        ok_or_typed(command::trapezoid(a, b, c, d / 100.0), |p| {
            prop_assert!(p.end_time().is_finite());
            Ok(())
        })?;
        ok_or_typed(command::s_curve(a, b, c, d, 0.0), |p| {
            ok_or_typed(profile::to_bspline(&p), |_| Ok(()))
        })?;
        ok_or_typed(Command::from_spec(&spec), |cmd| {
            ok_or_typed(cmd.shaped(&s), |shaped| {
                prop_assert!(!shaped.end_time().is_nan());
                Ok(())
            })?;
            ok_or_typed(cmd.to_piecewise(), |p| {
                let _ = p.eval(a);
                ok_or_typed(p.derivative(), |_| Ok(()))?;
                ok_or_typed(p.integral(), |_| Ok(()))
            })
        })?;
        if let input_shaping::command::CommandSpec::Profile(p) = &spec {
            ok_or_typed(profile::pulse_durations(p), |_| Ok(()))?;
        }
        ok_or_typed(profile::position_from_pulses(&xs, a), |_| Ok(()))?;
        ok_or_typed(command::StreamingShaper::new(&s, period), |mut f| {
            let mut out = vec![0.0; xs.len()];
            f.process(&xs, &mut out);
            for &x in &xs {
                let _ = f.push(x);
            }
            Ok(())
        })?;
        let _ = metrics::peak_valley_count(&xs);
        ok_or_typed(two_mass::rotary_omega_rad_s(a, b, c, d), |_| Ok(()))?;
        ok_or_typed(two_mass::cantilever_stiffness(a, b, c), |_| Ok(()))?;
        ok_or_typed(two_mass::arm_omega_rad_s(a, b, c, d, period), |_| Ok(()))?;
    }

    #[test]
    fn simulation_and_spectrum(
        plant in plant_spec(),
        command in command_spec(),
        shaper_spec in prop::option::of(cheap_shaper_spec()),
        duration in prop::option::of(num(0.5..20.0)),
        (period, rate) in (prop::option::of(num(1e-4..0.05)), prop::option::of(num(10.0..5000.0))),
        (from_hz, to_hz, points) in (num(0.0..5.0), prop::option::of(num(1.0..20.0)), count(2..600)),
        signal in prop::sample::select(vec![SpectrumSignal::Velocity, SpectrumSignal::Position, SpectrumSignal::Acceleration]),
    ) {
        let shaper = shaper_spec.map(|shaper| scenario::ShaperRequest { modes: None, shaper });
        let spec = SimulationSpec {
            plant: plant.clone(),
            command: command.clone(),
            shaper: shaper.clone(),
            impulses: None,
            duration,
            sample_period: period,
            sample_rate_hz: rate,
        };
        ok_or_typed(scenario::run(&spec), |r| {
            prop_assert!(!r.time.is_empty());
            prop_assert_eq!(r.time.len(), r.unshaped.trajectory.endpoint.len());
            Ok(())
        })?;
        let spec = SpectrumSpec {
            command,
            shaper,
            impulses: None,
            plant: Some(plant),
            from_hz,
            to_hz,
            points,
            signal,
        };
        ok_or_typed(scenario::spectrum_for(&spec), |r| {
            prop_assert_eq!(r.magnitude.len(), r.frequency_hz.len());
            Ok(())
        })?;
    }

    #[test]
    fn plants_validate(plant in plant_spec()) {
        ok_or_typed(Plant::from_spec(&plant), |p| ok_or_typed(p.modes(), |_| Ok(())))?;
    }

    #[test]
    fn robustness_tables(
        mode in mode_spec(),
        vtol in num(0.001..0.5),
        specs in prop::collection::vec(cheap_shaper_spec(), 0..4),
    ) {
        if let Ok(m) = Mode::from_spec(&mode) {
            ok_or_typed(robustness::robustness_table(&specs, &m, vtol), |rows| {
                prop_assert_eq!(rows.len(), specs.len());
                Ok(())
            })?;
        }
    }
}

proptest! {
    #![proptest_config(config(400))]

    /// The solver's public entry point with arbitrary problems (not only those the families
    /// build).
    #[test]
    fn solver_on_any_problem(
        zeros in prop::collection::vec((num(0.2..5.0), num(0.0..0.3), small_u32(0..3)), 0..3),
        limits in prop::collection::vec((num(0.2..5.0), num(0.0..0.3), num(0.01..0.2)), 0..3),
        bands in prop::collection::vec((num(0.3..1.0), num(0.0..0.5), num(0.0..0.1), num(0.01..0.2)), 0..2),
        (amin, amax, max_duration) in (num(-0.5..0.0), num(0.5..1.5), prop::option::of(num(0.5..10.0))),
    ) {
        let mut bs = Vec::new();
        for (lo, w, z, v) in bands {
            match solve::Tolerance::constant(v) {
                Ok(tolerance) => bs.push(solve::Band {
                    from_hz: lo,
                    to_hz: lo * (1.0 + w),
                    damping_from: z,
                    damping_to: z,
                    tolerance,
                }),
                Err(e) => check_error(&e)?,
            }
        }
        let problem = solve::Problem {
            zeros: zeros
                .into_iter()
                .map(|(frequency_hz, damping, derivatives)| solve::ZeroVibration { frequency_hz, damping, derivatives })
                .collect(),
            limits: limits
                .into_iter()
                .map(|(frequency_hz, damping, vtol)| solve::Limit { frequency_hz, damping, vtol })
                .collect(),
            bands: bs,
            amplitude_min: amin,
            amplitude_max: amax,
            max_duration,
        };
        if std::env::var("PROP_TRACE").is_ok() {
            eprintln!("problem: {problem:?}");
        }
        ok_or_typed(solve::minimum_duration(&problem), |d| {
            check_valid(&d.shaper).map_err(TestCaseError::fail)
        })?;
    }
}

/// A family name typed wrongly is a parse error naming `family`, not a panic.
#[test]
fn unknown_family_is_a_parse_error() {
    let r: Result<input_shaping::DesignRequest, _> =
        serde_json::from_str(r#"{"family":"zz","modes":[{"frequencyHz":1}]}"#);
    assert!(r.is_err());
    let _ = ShaperSpec::Zv;
}
