//! The response to a shaped command computed from the shaper's convolution factors
//! (`simulate_shaped`, `Lti::respond_shaped`) against the same command shaped by the expanded
//! shaper and simulated knot by knot (`Command::shaped`, then `simulate`): random convolved
//! shapers (the multi-mode designs and random custom factors), random modal plants
//! (mismatched, damped from 0 to 0.95, mostly lightly), several commands. Every output row, every sample, to
//! rounding.

mod common;

use common::Rng;
use input_shaping::command::{Command, CommandSpec};
use input_shaping::design::design_for;
use input_shaping::plant::{ModalPlant, Plant};
use input_shaping::simulate::{simulate, simulate_shaped, Trajectory};
use input_shaping::{Impulse, Mode, Shaper, ShaperSpec};

/// Largest difference between two trajectories over every row and sample, relative to the
/// largest |value| of that row (at least 1).
fn difference(a: &Trajectory, b: &Trajectory) -> f64 {
    let rows = |t: &Trajectory| {
        [
            t.base_position.clone(),
            t.base_velocity.clone(),
            t.base_acceleration.clone(),
            t.endpoint.clone(),
            t.endpoint_velocity.clone(),
            t.endpoint_acceleration.clone(),
            t.deflection.clone(),
        ]
    };
    assert_eq!(a.time, b.time);
    rows(a)
        .iter()
        .zip(rows(b).iter())
        .map(|(x, y)| {
            assert_eq!(x.len(), y.len());
            let scale = y.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
            x.iter()
                .zip(y)
                .map(|(p, q)| (p - q).abs() / scale)
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

fn random_modes(rng: &mut Rng, n: usize) -> Vec<Mode> {
    (0..n)
        .map(|_| Mode::new(0.5 + 30.0 * rng.uniform(), 0.95 * rng.uniform().powi(2)).unwrap())
        .collect()
}

fn commands() -> Vec<Command> {
    [
        CommandSpec::Trapezoid {
            distance: 1.0,
            max_velocity: 0.75,
            max_acceleration: 8.0,
            start: 0.0,
        },
        CommandSpec::SCurve {
            distance: -0.3,
            max_velocity: 0.5,
            max_acceleration: 5.0,
            max_jerk: 200.0,
            start: 0.05,
        },
        CommandSpec::Step {
            distance: 1.0,
            start: 0.0,
        },
        CommandSpec::Ramp {
            slope: 0.4,
            start: 0.01,
        },
    ]
    .iter()
    .map(|s| Command::from_spec(s).unwrap())
    .collect()
}

/// Compares the factored and the expanded response for `shaper` on a modal plant with `plant`
/// modes; returns the difference.
fn compare(shaper: &Shaper, plant: &[Mode], command: &Command, samples: usize) -> f64 {
    let participation = vec![1.0 / plant.len() as f64; plant.len()];
    let plant = Plant::Modal(ModalPlant::new(plant.to_vec(), participation).unwrap());
    let duration = command.end_time() + shaper.duration() + 2.0;
    let period = duration / (samples - 1) as f64;
    let factored = simulate_shaped(&plant, command, shaper, period, duration).unwrap();
    let expanded = simulate(&plant, &command.shaped(shaper).unwrap(), period, duration).unwrap();
    difference(&factored, &expanded)
}

#[test]
fn multi_mode_designs_respond_as_their_expanded_commands() {
    let mut rng = Rng(0x5eed_0024);
    let specs = [
        ShaperSpec::Zv,
        ShaperSpec::Zvd,
        ShaperSpec::Zvdd,
        ShaperSpec::Zvdn { derivatives: 3 },
        ShaperSpec::Mzv,
        ShaperSpec::Ei { vtol: 0.05 },
    ];
    let mut worst: f64 = 0.0;
    for round in 0..24 {
        let modes = random_modes(&mut rng, 1 + round % 4);
        let spec = &specs[round % specs.len()];
        let Ok(shaper) = design_for(spec, &modes) else {
            continue;
        };
        let mismatch = 0.7 + 0.6 * rng.uniform();
        let plant: Vec<Mode> = modes
            .iter()
            .map(|m| Mode::new(m.frequency_hz() * mismatch, m.damping()).unwrap())
            .collect();
        for command in commands() {
            let d = compare(&shaper, &plant, &command, 300 + 50 * (round % 5));
            assert!(
                d < 1e-9,
                "round {round}, {} over {} modes: factored response differs by {d:e}",
                spec.name(),
                modes.len()
            );
            worst = worst.max(d);
        }
    }
    assert!(worst > 0.0, "the two paths were never compared");
    eprintln!("multi-mode designs: worst relative difference {worst:e}");
}

#[test]
fn random_convolved_shapers_respond_as_their_expanded_commands() {
    let mut rng = Rng(0x0024_f00d);
    let mut worst: f64 = 0.0;
    for round in 0..30 {
        // Two to four random factors, some with negative amplitudes, of 1 to 5 impulses.
        let mut shaper = Shaper::identity();
        for _ in 0..2 + round % 3 {
            let n = 1 + (rng.uniform() * 5.0) as usize;
            let factor = Shaper::new(
                (0..n)
                    .map(|i| Impulse {
                        time: if i == 0 { 0.0 } else { 0.4 * rng.uniform() },
                        amplitude: rng.normal(),
                    })
                    .collect(),
            )
            .unwrap();
            shaper = shaper.convolve(&factor).unwrap();
        }
        let plant = random_modes(&mut rng, 1 + round % 6);
        for command in commands() {
            let d = compare(&shaper, &plant, &command, 200 + 37 * (round % 7));
            assert!(
                d < 1e-9,
                "round {round}: factored response differs by {d:e}"
            );
            worst = worst.max(d);
        }
    }
    // Not bit for bit: the factored path ran (the expanded one would agree exactly).
    assert!(worst > 0.0, "the two paths were never compared");
    eprintln!("random convolved shapers: worst relative difference {worst:e}");
}

#[test]
fn six_modes_zvdd_responds_as_its_expanded_command() {
    // Issue 24's six modes: ZVDD over them has 4⁶ = 4096 impulses, the shaped trapezoid 16 384
    // knots.
    let modes: Vec<Mode> = [1.2, 3.4, 7.9, 13.0, 21.0, 34.0]
        .iter()
        .map(|&f| Mode::new(f, 0.02).unwrap())
        .collect();
    let shaper = design_for(&ShaperSpec::Zvdd, &modes).unwrap();
    assert_eq!(shaper.len(), 4096);
    let plant: Vec<Mode> = modes
        .iter()
        .map(|m| Mode::new(m.frequency_hz() * 1.1, m.damping()).unwrap())
        .collect();
    let d = compare(&shaper, &plant, &commands()[0], 1000);
    assert!(d > 0.0 && d < 1e-9, "factored response differs by {d:e}");
    eprintln!("six-mode ZVDD: relative difference {d:e}");
}

/// A window that ends inside the move: the later knots land past the last sample (their
/// impulses are skipped, and a knot whose first sample lies past the window reads nothing of
/// the response's table). The same response as the expanded command's.
#[test]
fn knots_past_the_samples_respond_as_the_expanded_command() {
    let modes: Vec<Mode> = [2.0, 5.5]
        .iter()
        .map(|&f| Mode::new(f, 0.03).unwrap())
        .collect();
    let shaper = design_for(&ShaperSpec::Zvd, &modes).unwrap();
    let plant: Vec<Mode> = modes
        .iter()
        .map(|m| Mode::new(m.frequency_hz() * 1.07, 0.05).unwrap())
        .collect();
    let participation = vec![0.5; 2];
    let plant = Plant::Modal(ModalPlant::new(plant, participation).unwrap());
    let late = &commands()[0];
    let (period, duration) = (0.005, 0.6);
    let factored = simulate_shaped(&plant, late, &shaper, period, duration).unwrap();
    let expanded = simulate(&plant, &late.shaped(&shaper).unwrap(), period, duration).unwrap();
    let d = difference(&factored, &expanded);
    assert!(
        d > 0.0 && d < 1e-9,
        "a window ending inside the move differs by {d:e}"
    );
}

/// `Lti::respond_shaped` takes factors with times from 0 (a shaper's): given a negative time
/// it declines (`None`: the caller expands the command) instead of reading its table before
/// its start.
#[test]
fn a_factor_with_a_negative_time_is_declined() {
    let plant = ModalPlant::new(vec![Mode::new(3.0, 0.02).unwrap()], vec![1.0]).unwrap();
    let Command::Piecewise(base) = &commands()[0] else {
        panic!("a trapezoid is piecewise");
    };
    let factor = [
        Impulse {
            time: -0.1,
            amplitude: 0.5,
        },
        Impulse {
            time: 0.2,
            amplitude: 0.5,
        },
    ];
    let lti = plant.to_lti();
    assert!(lti
        .respond_shaped(base, &[&factor], 0.01, 300)
        .unwrap()
        .is_none());
    let shifted = factor.map(|i| Impulse {
        time: i.time + 0.1,
        ..i
    });
    assert!(lti
        .respond_shaped(base, &[&shifted], 0.01, 300)
        .unwrap()
        .is_some());
}
