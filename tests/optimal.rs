//! The optimised shapers of issue 25 (crate/measure/optimal.rs) on the independently generated
//! test set `tests/data/klipper/` (benches/reference/sweep_testset.py):
//!
//! 1. the best mainline-Klipper shaper never scores worse than Klipper's own pick and never
//!    leaves more vibration than max(pick's, 5 %), by Klipper's own scoring (the crate's
//!    reproduction, itself checked against benches/reference/klipper_reference.py);
//! 2. the custom shaper scores no worse than the mainline one, within each firmware's limits;
//! 3. it is not tuned to noise: designed on one run of a machine, its score on the second run
//!    stays within 10 % of its score on the first;
//! 4. the mainline search is at least as good as an independent dense grid
//!    (benches/reference/optimal_reference.py, numpy: `optimal_reference.json`) to 0.5 %.
//!
//! Native only (reads files).

use input_shaping::export::{
    self,
    firmware::{firmware_config, AxisShaper},
};
use input_shaping::measure::klipper::{
    find_best_shaper, klipper_figures_on, CalibrationData, Channel, Dataset, FitOptions,
};
use input_shaping::measure::optimal::{
    optimal, Firmware, OptimalOptions, OptimalReport, MIN_CUSTOM_AMPLITUDE,
};
use input_shaping::measure::recommend::MeasuredMode;
use input_shaping::shaper::{Impulse, Shaper};
use std::path::Path;

const DIR: &str = "tests/data/klipper";

/// A `resonances_*.csv` (`freq,psd_x,psd_y,psd_z,psd_xyz`) read and normalised as Klipper's
/// `calibrate_shaper.py` reads it (minimal reader; the product's is `parseRecording`).
fn read(name: &str) -> CalibrationData {
    let text = std::fs::read_to_string(Path::new(DIR).join(name)).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(
        header.starts_with("freq,psd_x,psd_y,psd_z,psd_xyz"),
        "{name}"
    );
    let rows: Vec<Vec<f64>> = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let col = |i: usize| rows.iter().map(|r| r[i]).collect::<Vec<f64>>();
    let mut d = CalibrationData::new(
        Dataset::new(name, col(0), col(4), Some([col(1), col(2), col(3)]), false).unwrap(),
    );
    d.normalize_to_frequencies();
    d
}

fn run(name: &str, firmware: Firmware) -> (CalibrationData, OptimalReport) {
    let data = read(name);
    let options = OptimalOptions {
        firmware,
        ..OptimalOptions::default()
    };
    let r = optimal(&data, &[], &options).unwrap();
    (data, r)
}

/// The guarantees of items 1 and 2 on one file.
fn check(name: &str, firmware: Firmware) -> OptimalReport {
    let (data, r) = run(name, firmware);
    // Row 0 is Klipper's own pick.
    let fit = find_best_shaper(&data, &FitOptions::default()).unwrap();
    let best = &fit.families[fit.best];
    let pick = &r.rows[0];
    assert_eq!(pick.kind, "klipper");
    assert_eq!(pick.family, best.name, "{name}");
    assert_eq!(pick.shaper_freq_hz, Some(best.pick.freq), "{name}");
    assert!((pick.klipper.score - best.pick.score).abs() <= 1e-12 * best.pick.score);
    // Every row's figures are Klipper's own, recomputed here on the row's impulses.
    for row in &r.rows {
        let s = Shaper::new(row.shaper.impulses.clone()).unwrap();
        let f = klipper_figures_on(&s, &data, None, 5.0, None, Channel::Sum).unwrap();
        assert!(
            (f.score - row.klipper.score).abs() <= 1e-12 * f.score,
            "{name}"
        );
        assert!(
            (f.vibrations - row.klipper.vibrations).abs() <= 1e-12,
            "{name}"
        );
    }
    let cap = pick.klipper.vibrations.max(0.05) + 1e-12;
    let main = &r.rows[1];
    assert_eq!(main.kind, "mainline");
    assert!(
        main.klipper.score <= pick.klipper.score * (1.0 + 1e-12),
        "{name}: mainline {} > pick {}",
        main.klipper.score,
        pick.klipper.score
    );
    assert!(main.klipper.vibrations <= cap, "{name}");
    assert!(main.improvement >= -1e-12);
    if let Some(limits) = firmware.limits() {
        let custom = &r.rows[2];
        assert_eq!(custom.kind, "custom");
        assert!(
            custom.klipper.score <= main.klipper.score * (1.0 + 1e-12),
            "{name}: custom {} > mainline {}",
            custom.klipper.score,
            main.klipper.score
        );
        assert!(custom.klipper.vibrations <= cap, "{name}");
        let imps = &custom.shaper.impulses;
        assert!(
            imps.len() >= 2 && imps.len() <= limits.max_impulses,
            "{name}"
        );
        let sum: f64 = imps.iter().map(|i| i.amplitude).sum();
        assert!((sum - 1.0).abs() < 1e-9);
        assert!(imps
            .iter()
            .all(|i| i.amplitude >= MIN_CUSTOM_AMPLITUDE * (1.0 - 1e-9)));
        let duration = imps.last().unwrap().time;
        assert!(duration <= limits.max_duration_s && duration >= limits.min_duration_s);
        assert!(imps.windows(2).all(|w| w[1].time > w[0].time));
        // The config text comes from the export layer (crate::export::firmware), which checks
        // the firmware's limits again as written.
        let shaper = Shaper::new(
            imps.iter()
                .map(|i| Impulse {
                    time: i.time,
                    amplitude: i.amplitude,
                })
                .collect(),
        )
        .unwrap();
        let axis = [AxisShaper::custom("x", &shaper)];
        match firmware {
            Firmware::Reprapfirmware => {
                let text = firmware_config(export::firmware::Firmware::Rrf, &axis)
                    .unwrap()
                    .text;
                assert!(text.contains("M593 P\"custom\" H"), "{text}");
            }
            _ => {
                let text = firmware_config(export::firmware::Firmware::Kalico, &axis)
                    .unwrap()
                    .text;
                assert!(text.contains("shaper_type_x: custom"), "{text}");
            }
        }
        assert_eq!(r.recommended, 2);
    } else {
        assert_eq!(r.rows.len(), 2);
        assert_eq!(r.recommended, 1);
    }
    assert!(!r.note.is_empty());
    r
}

#[test]
fn guarantees_single_modes() {
    for name in [
        "resonances_x_z008f47.csv",
        "resonances_x_z018f61.csv",
        "resonances_y_noisy47.csv",
    ] {
        check(name, Firmware::Reprapfirmware);
    }
}

#[test]
fn guarantees_several_modes() {
    for name in ["resonances_y_three.csv", "resonances_x_two45x14.csv"] {
        check(name, Firmware::Kalico);
    }
    // Mainline Klipper only: two rows.
    check("resonances_y_m1.csv", Firmware::Klipper);
}

#[test]
fn guarantees_far_outside_klippers_scan() {
    // Modes at 1, 3.4 and 11 Hz: Klipper's scan (from 21 Hz up) leaves 64 % of the vibration;
    // the mainline search goes down to 5 Hz and must cut it (here to under 1 %).
    let r = check("resonances_x_slow3modes.csv", Firmware::Reprapfirmware);
    assert!(r.rows[0].klipper.vibrations > 0.5);
    assert!(r.rows[1].klipper.vibrations < 0.01);
}

#[test]
fn robust_across_two_runs_of_one_machine() {
    // Issue 25 item 5: designed on run 1, scored on run 2 (same machine, other noise).
    let (_, r) = run("resonances_x_m1.csv", Firmware::Kalico);
    let run2 = read("resonances_x_m1run2.csv");
    for row in &r.rows[1..] {
        let s = Shaper::new(row.shaper.impulses.clone()).unwrap();
        let f = klipper_figures_on(&s, &run2, None, 5.0, None, Channel::Sum).unwrap();
        let ratio = f.score / row.klipper.score;
        assert!(
            (0.9..=1.1).contains(&ratio),
            "{}: run 1 {} run 2 {}",
            row.kind,
            row.klipper.score,
            f.score
        );
    }
}

#[test]
fn at_least_as_good_as_an_independent_dense_grid() {
    // benches/reference/optimal_reference.py: damping_ratio every 0.025, shaper_freq every
    // 0.25 Hz over [½, 2] × Klipper's pick frequency, every family, numpy figures.
    let text = std::fs::read_to_string("benches/reference/optimal_reference.json").unwrap();
    let rows: serde_json::Value = serde_json::from_str(&text).unwrap();
    for entry in rows.as_array().unwrap() {
        let file = entry["file"].as_str().unwrap();
        if file != "resonances_y_m1.csv" && file != "resonances_x_two45x14.csv" {
            continue;
        }
        let (_, r) = run(file, Firmware::Klipper);
        let k = entry["klipper"]["score"].as_f64().unwrap();
        assert!((r.rows[0].klipper.score - k).abs() <= 1e-9 * k, "{file}");
        let grid = entry["mainline"]["score"].as_f64().unwrap();
        assert!(
            r.rows[1].klipper.score <= grid * 1.005,
            "{file}: ours {} grid {grid}",
            r.rows[1].klipper.score
        );
    }
}

#[test]
fn measured_modes_widen_the_damping_set() {
    let data = read("resonances_x_z008f47.csv");
    let modes = [MeasuredMode {
        frequency_hz: 47.0,
        damping: 0.08,
        frequency_uncertainty_hz: 0.3,
        damping_uncertainty: 0.01,
    }];
    let r = optimal(&data, &modes, &OptimalOptions::default()).unwrap();
    for z in [0.06, 0.075, 0.08, 0.1, 0.1, 0.15] {
        assert!(
            r.damping_tested.iter().any(|d| (d - z).abs() < 1e-12),
            "{z} in {:?}",
            r.damping_tested
        );
    }
    // Still Klipper's guarantees under Klipper's own scoring.
    assert!(r.rows[1].klipper.score <= r.rows[0].klipper.score * (1.0 + 1e-12));
}

/// The measured modes' uncertainty is a constraint, not the objective: every optimised row
/// leaves no more R over the widened set (ζ ± 2σ, f(1 ± 2σ_f/f)) than max(Klipper pick's R
/// over that set, 5 %), and within that the rows are ranked by Klipper's own score. Ranked by
/// the widened score instead, the optimised shapers gained nothing on real files (every public
/// Klipper file of docs/measured-data.md, *On real recordings*): the pick, held only to
/// Klipper's three ratios, stayed the most robust. Here (47.3 ± 0.5 Hz, ζ 0.07 ± 0.012, as real files give) the
/// custom shaper must still score below Klipper's pick, as it does without modes.
#[test]
fn measured_modes_bound_the_robust_vibrations_and_klippers_score_ranks() {
    let data = read("resonances_x_z008f47.csv");
    let modes = [MeasuredMode {
        frequency_hz: 47.3,
        damping: 0.07,
        frequency_uncertainty_hz: 0.5,
        damping_uncertainty: 0.012,
    }];
    let options = OptimalOptions {
        firmware: Firmware::Reprapfirmware,
        ..OptimalOptions::default()
    };
    let r = optimal(&data, &modes, &options).unwrap();
    let pick = &r.rows[0];
    let limit = pick.robust_vibrations.max(0.05);
    for row in &r.rows[1..] {
        assert!(
            row.robust_vibrations <= limit + 1e-12,
            "{}: R over the widened set {} > {limit}",
            row.kind,
            row.robust_vibrations
        );
        assert!(row.klipper.score <= pick.klipper.score * (1.0 + 1e-12));
    }
    let custom = &r.rows[2];
    assert_eq!(custom.kind, "custom");
    assert!(
        custom.klipper.score < 0.97 * pick.klipper.score,
        "custom {} vs pick {}",
        custom.klipper.score,
        pick.klipper.score
    );
}

/// `customMethod: both` keeps the better of the continuation and the grid program, each run on
/// its own (`CustomMethod::Both`'s contract). Run as one path sharing the growth and the
/// evaluation budget, it scored worse than the continuation alone on a real file (bassco
/// ender3 y with its identified modes: −4.0 % against Klipper's pick vs −8.1 %;
/// docs/measured-data.md, *On real recordings*); that file is not in the repository and on
/// this test set the one-path version happens to pass too. Here the grid alone scores below
/// the continuation alone (0.001475 vs 0.001483), so a `both` that kept the continuation's
/// result fails.
#[cfg(feature = "solver")]
#[test]
fn both_methods_keep_the_better_custom_shaper() {
    use input_shaping::measure::optimal::CustomMethod;
    let data = read("resonances_y_m1.csv");
    let modes = [MeasuredMode {
        frequency_hz: 37.6,
        damping: 0.12,
        frequency_uncertainty_hz: 0.3,
        damping_uncertainty: 0.01,
    }];
    let score = |method| {
        let options = OptimalOptions {
            firmware: Firmware::Reprapfirmware,
            custom_method: method,
            ..OptimalOptions::default()
        };
        optimal(&data, &modes, &options).unwrap().rows[2]
            .klipper
            .score
    };
    let both = score(CustomMethod::Both);
    for method in [CustomMethod::Continuation, CustomMethod::Grid] {
        let alone = score(method);
        assert!(
            both <= alone * (1.0 + 1e-12),
            "both {both} above {method:?} alone {alone}"
        );
    }
}

/// A mode whose peak stays under Klipper's threshold (P_max/20) cannot change Klipper's R, so
/// its uncertainty must not widen the robust score: on real spectra a weak second or third peak
/// is often fitted with a wide uncertainty (118.5 ± 7.5 Hz on a public Voron 2.4 file), and
/// that band, applied to every bin, took all of the optimised shaper's gain.
#[test]
fn modes_under_klippers_threshold_do_not_widen_the_robust_score() {
    let data = read("resonances_x_z008f47.csv");
    // The file's only mode is 47.3 Hz; at 150 Hz its PSD is far under P_max/20.
    let weak = [MeasuredMode {
        frequency_hz: 150.0,
        damping: 0.05,
        frequency_uncertainty_hz: 8.0,
        damping_uncertainty: 0.04,
    }];
    let with = optimal(&data, &weak, &OptimalOptions::default()).unwrap();
    let without = optimal(&data, &[], &OptimalOptions::default()).unwrap();
    assert_eq!(with.damping_tested, without.damping_tested);
    assert_eq!(with.damping_tested, vec![0.075, 0.1, 0.15]);
    for (a, b) in with.rows.iter().zip(&without.rows) {
        assert_eq!(a.klipper.score, b.klipper.score, "{}", a.kind);
    }
    // The same mode at the file's peak does widen it (as measured_modes_widen_the_damping_set).
    let strong = [MeasuredMode {
        frequency_hz: 47.3,
        ..weak[0]
    }];
    let r = optimal(&data, &strong, &OptimalOptions::default()).unwrap();
    assert!(
        r.damping_tested.iter().any(|&z| (z - 0.13).abs() < 1e-12),
        "{:?}",
        r.damping_tested
    );
}

#[test]
fn bad_input_is_refused_with_the_field() {
    let data = read("resonances_x_z008f47.csv");
    let e = optimal(
        &data,
        &[],
        &OptimalOptions {
            uncertainty_sigmas: 11.0,
            ..OptimalOptions::default()
        },
    )
    .unwrap_err();
    assert_eq!(e.field(), Some("uncertaintySigmas"));
    let bad = [MeasuredMode {
        frequency_hz: -1.0,
        damping: 0.1,
        frequency_uncertainty_hz: 0.0,
        damping_uncertainty: 0.0,
    }];
    let e = optimal(&data, &bad, &OptimalOptions::default()).unwrap_err();
    assert!(e.field().unwrap().starts_with("modes[0]"), "{e:?}");
    let zero = CalibrationData::new(
        Dataset::new("zero", vec![0.0, 1.0, 2.0], vec![0.0; 3], None, true).unwrap(),
    );
    let e = optimal(&zero, &[], &OptimalOptions::default()).unwrap_err();
    assert!(e.field().is_some(), "{e:?}");
}

#[test]
fn recommend_criterion_optimal_ranks_the_optimised_shaper_first() {
    use input_shaping::measure::optimal::Firmware;
    use input_shaping::measure::recommend::{
        recommend, Criterion, MeasuredSpectrum, RecommendOptions,
    };
    // The raw (unnormalised) PSD, as identifyModes' spectrum or a resonances file gives it:
    // recommend normalises it as Klipper does, so Klipper's pick is the golden one.
    let text = std::fs::read_to_string(Path::new(DIR).join("resonances_x_z008f47.csv")).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let spectrum = MeasuredSpectrum {
        frequency_hz: rows.iter().map(|r| r[0]).collect(),
        psd: rows.iter().map(|r| r[4]).collect(),
        ..MeasuredSpectrum::default()
    };
    let options = RecommendOptions {
        criterion: Criterion::Optimal,
        firmware: Firmware::Reprapfirmware,
        ..RecommendOptions::default()
    };
    let r = recommend(&spectrum, &[], &options).unwrap();
    assert_eq!(r.criterion, Criterion::Optimal);
    assert_eq!(r.recommended, 0);
    assert_eq!(r.ranked.len(), 3);
    assert_eq!(r.ranked[0].family, "custom");
    let pick = r
        .ranked
        .iter()
        .find(|c| c.label.contains("Klipper's pick"))
        .unwrap();
    let fit = find_best_shaper(&read("resonances_x_z008f47.csv"), &FitOptions::default()).unwrap();
    let best = &fit.families[fit.best];
    assert_eq!(pick.family, best.name);
    let expected = format!("{} {:.1} Hz", best.name, best.pick.freq);
    assert!(
        pick.label.starts_with(&expected),
        "{} vs {expected}",
        pick.label
    );
    // Each row says its kind; a family row carries the mode a config writes (shaper_freq at
    // damping_ratio, Klipper's pick at Klipper's 0.1), a custom row none.
    assert_eq!(pick.kind, Some("klipper"));
    assert_eq!(r.ranked[0].kind, Some("custom"));
    assert!(r.ranked[0].modes.is_empty());
    assert_eq!(pick.modes.len(), 1);
    assert!((pick.modes[0].frequency_hz - best.pick.freq).abs() < 1e-9);
    assert!((pick.modes[0].damping - fit.damping_ratio).abs() < 1e-12);
    let mainline = r
        .ranked
        .iter()
        .find(|c| c.kind == Some("mainline"))
        .unwrap();
    assert!(mainline
        .label
        .contains(&format!("{:.2} Hz", mainline.modes[0].frequency_hz)));
    let score = |i: usize| r.ranked[i].klipper_score.unwrap();
    assert!(score(0) <= pick.klipper_score.unwrap());
    assert!(r.note.as_deref().is_some_and(|n| !n.is_empty()));
}

/// The score table of docs/measured-data.md (*Scores on the test set*): every
/// `resonances_*.csv`, RepRapFirmware limits, the custom method from `OPTIMAL_METHOD`
/// (`continuation` by default, `grid`, `both`). Prints markdown rows and the medians.
/// `cargo test --release --test optimal -- --ignored --nocapture score_table`.
#[test]
#[ignore = "prints the docs' table (slow in debug builds)"]
fn score_table() {
    use input_shaping::measure::optimal::CustomMethod;
    let method = match std::env::var("OPTIMAL_METHOD").as_deref() {
        Ok("grid") => CustomMethod::Grid,
        Ok("both") => CustomMethod::Both,
        _ => CustomMethod::Continuation,
    };
    let mut names: Vec<String> = std::fs::read_dir(DIR)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with("resonances_") && n.ends_with(".csv"))
        .collect();
    names.sort();
    let (mut main_gain, mut custom_gain) = (Vec::new(), Vec::new());
    println!(
        "| file | Klipper's pick | score / R / smoothing | best mainline | score / R / smoothing \
         | custom | score / R / smoothing | ms |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    for name in &names {
        let data = read(name);
        let options = OptimalOptions {
            firmware: Firmware::Reprapfirmware,
            custom_method: method,
            ..OptimalOptions::default()
        };
        let t0 = std::time::Instant::now();
        let r = optimal(&data, &[], &options).unwrap();
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        let cell = |i: usize| {
            let row = &r.rows[i];
            let change = if i == 0 {
                String::new()
            } else {
                format!(" ({:+.1} %)", -100.0 * row.improvement)
            };
            format!(
                "{:.6}{change} / {:.2} % / {:.4}",
                row.klipper.score,
                100.0 * row.klipper.vibrations,
                row.klipper.smoothing
            )
        };
        let label = |i: usize| {
            let row = &r.rows[i];
            match (i, row.shaper_freq_hz, row.damping_ratio) {
                (0, Some(f), _) => format!("{} {f:.1} Hz", row.family),
                (_, Some(f), Some(z)) => format!("{} {f:.2} Hz ζ {z:.3}", row.family),
                _ => format!("custom ({} imp.)", row.shaper.impulses.len()),
            }
        };
        println!(
            "| {name} | {} | {} | {} | {} | {} | {} | {ms:.0} |",
            label(0),
            cell(0),
            label(1),
            cell(1),
            label(2),
            cell(2)
        );
        main_gain.push(r.rows[1].improvement);
        custom_gain.push(r.rows[2].improvement);
        #[cfg(feature = "solver")]
        if std::env::var("OPTIMAL_BOUND").is_ok() {
            use input_shaping::measure::optimal::no_vibration_bound;
            for last_min in [0.0, MIN_CUSTOM_AMPLITUDE] {
                if let Some(b) = no_vibration_bound(&data, 5.0, last_min).unwrap() {
                    let pick = r.rows[0].klipper.score;
                    println!(
                        "bound {name} last≥{last_min}: score {:.6} ({:+.1} % vs pick), {} imp., \
                         smallest {:.4}, duration {:.4} s",
                        b.score,
                        100.0 * (b.score / pick - 1.0),
                        b.impulses,
                        b.smallest_amplitude,
                        b.duration_s
                    );
                }
            }
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    };
    println!(
        "median improvement over Klipper's pick ({} files): mainline {:.1} %, custom {:.1} %",
        names.len(),
        100.0 * median(&mut main_gain),
        100.0 * median(&mut custom_gain)
    );
}

#[cfg(feature = "solver")]
#[test]
fn no_vibration_bound_is_a_floor_below_klippers_pick() {
    // The convex grid program's least smoothing with R = 0 (last impulse ≥ 2 %): Klipper's
    // score 0.01 × smoothing. The continuation's custom shaper leaves almost no vibration here
    // (R < 0.1 %), so it cannot score much below that floor (only the grid's resolution and a
    // trade of a little R separate them); and on this clean single mode the floor lies well
    // below Klipper's pick (mzv leaves room).
    use input_shaping::measure::optimal::no_vibration_bound;
    let name = "resonances_x_z008f47.csv";
    let (data, r) = run(name, Firmware::Reprapfirmware);
    let b = no_vibration_bound(&data, 5.0, MIN_CUSTOM_AMPLITUDE)
        .unwrap()
        .unwrap();
    assert!((b.score - 0.01 * b.smoothing).abs() <= 1e-15);
    assert!(b.impulses >= 2 && b.duration_s > 0.0);
    let custom = &r.rows[2].klipper;
    assert!(custom.vibrations < 1e-3, "{custom:?}");
    assert!(
        custom.score >= 0.97 * b.score,
        "custom {} below the floor {}",
        custom.score,
        b.score
    );
    assert!(b.score < 0.95 * r.rows[0].klipper.score, "{b:?}");
}

/// Why custom shapers keep positive amplitudes although Kalico (and RepRapFirmware's parser)
/// take negative ones: Klipper's smoothing (`_get_shaper_smoothing`) is the 180° reversal's
/// shortfall a/2 Σ Aᵢ(tᵢ − c)² — exact for a positive shaper, but a signed moment that negative
/// amplitudes drive to zero or below while the toolhead overshoots the reversal instead. The
/// convex floor program (`optimal_grid.rs`) with amplitudes ≥ −0.1 and |offsets| bounded found
/// the shaper below on `resonances_x_z008f47.csv` with no remaining vibration (2026-12-06,
/// docs/measured-data.md, *Where the score is left*): Klipper would score it ≤ 0. The corner
/// simulation (an independent computation: the shaped trapezoids of a planned path) shows what
/// it does: the reversal overshoots by more than Klipper's MZV falls short, and the square's
/// corners deviate twice as far.
#[test]
fn negative_amplitudes_game_klippers_smoothing() {
    use input_shaping::corner::{corner, plan, square, Axis, MotionLimits};
    use input_shaping::measure::klipper::klipper_shaper;
    use input_shaping::plant::ModalPlant;
    use input_shaping::smoothing::smoothing;
    use input_shaping::Mode;
    let impulses = [
        (0.0, -0.102_256),
        (0.016_996, 1.152_753),
        (0.036_265, -0.025_779),
        (0.041_305, 0.030_989),
        (0.045_875, -0.118_385),
        (0.047_486, 0.062_678),
    ];
    let negative = Shaper::new(
        impulses
            .iter()
            .map(|&(time, amplitude)| Impulse { time, amplitude })
            .collect(),
    )
    .unwrap()
    .normalized()
    .unwrap();
    let mzv = klipper_shaper("mzv", 48.2, 0.1)
        .unwrap()
        .normalized()
        .unwrap();
    // The nozzle follows the shaped command exactly (no mode takes part): only the shaper acts.
    let rigid = ModalPlant::new(vec![Mode::new(48.2, 0.1).unwrap()], vec![0.0]).unwrap();
    let limits = MotionLimits {
        velocity: 200.0,
        accel: 5000.0,
        square_corner_velocity: 5.0,
    };
    let reversal = plan(&[[0.0, 0.0], [40.0, 0.0], [0.0, 0.0]], &limits).unwrap();
    let square = plan(&square(40.0).unwrap(), &limits).unwrap();
    let print = |p, s| {
        corner(
            p,
            [
                Axis {
                    plant: &rigid,
                    shaper: Some(s),
                },
                Axis {
                    plant: &rigid,
                    shaper: Some(s),
                },
            ],
            2e-5,
            0.1,
        )
        .unwrap()
    };
    // Signed shortfall of the reversal at x = 40 (negative: the nozzle went past it).
    let shortfall = |s| {
        40.0 - print(&reversal, s).nozzle[0]
            .iter()
            .fold(f64::MIN, |m, &x| m.max(x))
    };
    let peak = |s| {
        print(&square, s)
            .deviation
            .iter()
            .fold(0.0_f64, |m, d| m.max(d.abs()))
    };
    let (sm_mzv, sm_neg) = (
        smoothing(&mzv, 5000.0, 5.0).unwrap(),
        smoothing(&negative, 5000.0, 5.0).unwrap(),
    );
    // For MZV Klipper's figure is the reversal's shortfall (its definition, to the sampling).
    assert!(
        (shortfall(&mzv) - sm_mzv).abs() < 1e-3,
        "{} vs {sm_mzv}",
        shortfall(&mzv)
    );
    // The negative shaper: Klipper's figure ≤ 0 — a better score than any positive shaper —
    // while the nozzle overshoots the reversal by more than MZV falls short of it and the
    // square's corners deviate more than twice as far.
    assert!(sm_neg <= 0.0, "{sm_neg}");
    assert!(-shortfall(&negative) > sm_mzv, "{}", shortfall(&negative));
    assert!(
        peak(&negative) > 2.0 * peak(&mzv),
        "{} vs {}",
        peak(&negative),
        peak(&mzv)
    );
}
