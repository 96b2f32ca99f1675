//! The printed corner (`crate::corner`, issue 23 item 3): Klipper's junction rule in closed
//! form, the planned axes against the path, a straight segment against the 1-D simulation, and
//! the shaped ringing after a corner against V times the unshaped one.

use input_shaping::command::{trapezoid, Command};
use input_shaping::corner::{corner, plan, ringing_tower, square, Axis, MotionLimits};
use input_shaping::design::zero_vibration::{zv, zvd};
use input_shaping::plant::{ModalPlant, Plant};
use input_shaping::simulate::simulate;
use input_shaping::vibration::residual_vibration;
use input_shaping::{Error, Mode, Shaper};
use std::f64::consts::PI;

fn limits(velocity: f64, accel: f64, scv: f64) -> MotionLimits {
    MotionLimits {
        velocity,
        accel,
        square_corner_velocity: scv,
    }
}

fn plant(f: f64, zeta: f64) -> ModalPlant {
    ModalPlant::new(vec![Mode::new(f, zeta).unwrap()], vec![1.0]).unwrap()
}

/// Klipper's `square_corner_velocity` is by definition the speed of a 90° corner
/// (docs/Config_Reference.md: "the maximum velocity (in mm/s) that the toolhead may travel a 90
/// degree corner at"): δ = scv²(√2 − 1)/a and s = sin 45° give v² = a·δ·s/(1 − s) = scv².
/// A turn by φ has s = cos(φ/2), so v² = scv²(√2 − 1)·s/(1 − s); a reversal stops; going
/// straight on keeps the top speed.
#[test]
fn junction_speeds_follow_klippers_rule() {
    let l = limits(300.0, 5000.0, 5.0);
    let p = plan(&[[0.0, 0.0], [100.0, 0.0], [100.0, 100.0]], &l).unwrap();
    assert!(
        (p.segments[0].v_end - 5.0).abs() < 1e-9,
        "{}",
        p.segments[0].v_end
    );
    assert_eq!(p.segments[0].v_end, p.segments[1].v_start);
    for phi_deg in [10.0_f64, 45.0, 90.0, 135.0, 170.0] {
        let phi = phi_deg.to_radians();
        let pts = [
            [0.0, 0.0],
            [100.0, 0.0],
            [100.0 + 100.0 * phi.cos(), 100.0 * phi.sin()],
        ];
        let v = plan(&pts, &l).unwrap().segments[0].v_end;
        let s = (phi / 2.0).cos();
        let expected = (25.0 * (2f64.sqrt() - 1.0) * s / (1.0 - s))
            .sqrt()
            .min(300.0);
        assert!(
            (v - expected).abs() < 1e-9 * expected,
            "turn {phi_deg}°: {v} vs {expected}"
        );
    }
    let reversal = plan(&[[0.0, 0.0], [100.0, 0.0], [50.0, 0.0]], &l).unwrap();
    assert_eq!(reversal.segments[0].v_end, 0.0);
    let straight = plan(&[[0.0, 0.0], [100.0, 0.0], [200.0, 0.0]], &l).unwrap();
    assert!((straight.segments[0].v_end - 300.0).abs() < 1e-9);
    // A corner between short segments is limited by their length (½·L·tan(θ/2)·a, θ = 90°
    // here) when that is lower, and by what the segment can reach from rest (v² = 2aL).
    let short = plan(&[[0.0, 0.0], [0.001, 0.0], [0.001, 0.001]], &l).unwrap();
    let v = short.segments[0].v_end;
    assert!((v * v - 0.5 * 0.001 * 5000.0).abs() < 1e-12, "{v}");
}

/// The planned axes pass through every corner at its time with the path's velocity there, end
/// at rest at the last point, and each segment's phases add up to its length.
#[test]
fn planned_axes_follow_the_path() {
    let pts = square(40.0).unwrap();
    let p = plan(&pts, &limits(150.0, 3000.0, 5.0)).unwrap();
    assert_eq!(p.segments.len(), 4);
    let (x, y) = (p.axis_command(0).unwrap(), p.axis_command(1).unwrap());
    for s in &p.segments {
        let (ex, ey) = (x.eval(s.t_start), y.eval(s.t_start));
        assert!((ex[0] - s.start[0]).abs() < 1e-9 && (ey[0] - s.start[1]).abs() < 1e-9);
        let mid = s.t_start + s.t_accel + 0.5 * s.t_cruise;
        let (vx, vy) = (x.eval(mid)[1], y.eval(mid)[1]);
        assert!((vx.hypot(vy) - s.v_cruise).abs() < 1e-9 * s.v_cruise);
        let covered = 0.5 * (s.v_start + s.v_cruise) * s.t_accel
            + s.v_cruise * s.t_cruise
            + 0.5 * (s.v_cruise + s.v_end) * s.t_decel;
        assert!(
            (covered - s.length).abs() < 1e-9,
            "{covered} vs {}",
            s.length
        );
    }
    let end = p.duration();
    for c in [&x, &y] {
        let e = c.eval(end + 1.0);
        assert!(
            e[0].abs() < 1e-9 && e[1].abs() < 1e-12 && e[2].abs() < 1e-12,
            "{e:?}"
        );
    }
    assert_eq!(
        p.axis_command(2).unwrap_err().field(),
        Some("axis"),
        "only X and Y"
    );
}

/// A straight move along X is the 1-D trapezoid, and its print is the 1-D simulation of the
/// same plant under it.
#[test]
fn a_straight_segment_is_the_one_dimensional_simulation() {
    let l = limits(120.0, 2500.0, 5.0);
    let p = plan(&[[0.0, 0.0], [30.0, 0.0]], &l).unwrap();
    let reference = trapezoid(30.0, 120.0, 2500.0, 0.0).unwrap();
    let x = p.axis_command(0).unwrap();
    for k in 0..400 {
        let t = (k as f64 + 0.5) * 0.001; // between knots: at one the two may differ by a rounding of its time
        let (a, b) = (x.eval(t), reference.eval(t));
        for i in 0..3 {
            assert!(
                (a[i] - b[i]).abs() < 1e-9 * (1.0 + b[i].abs()),
                "t {t}: {a:?} vs {b:?}"
            );
        }
    }
    let xp = plant(37.0, 0.04);
    let yp = plant(52.0, 0.03);
    let print = corner(
        &p,
        [
            Axis {
                plant: &xp,
                shaper: None,
            },
            Axis {
                plant: &yp,
                shaper: None,
            },
        ],
        1e-4,
        0.2,
    )
    .unwrap();
    let one_d = simulate(
        &Plant::Modal(xp.clone()),
        &Command::Piecewise(reference),
        1e-4,
        p.duration() + 0.2,
    )
    .unwrap();
    assert_eq!(print.nozzle[0].len(), one_d.endpoint.len());
    for (a, b) in print.nozzle[0].iter().zip(&one_d.endpoint) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    assert!(print.nozzle[1].iter().all(|y| y.abs() < 1e-12));
    // Never off the line sideways: the deviation is how far the nozzle overshoots an end.
    for (d, x) in print.deviation.iter().zip(&print.nozzle[0]) {
        let beyond = (x - 30.0).max(-x).max(0.0);
        assert!((d.abs() - beyond).abs() < 1e-9, "{d} at x = {x}");
    }
    assert!(
        print.deviation.iter().any(|d| d.abs() > 1e-4),
        "the stop rings past the end"
    );
}

/// A corner taken at the cruise speed v (velocity = square_corner_velocity, so the path does
/// not slow): X's velocity steps from v to 0. On an undamped mode of ω the unshaped wall after
/// the corner rings at v/ω (z'' + ω²z = v δ(t)); shaped, at V(ω)·v/ω after the shaper
/// (Singhose 2009 eq. 11: the residual of a shaped input is V times the unshaped one). The
/// first segment's acceleration lasts exactly two periods of the mode, so it leaves no
/// vibration of its own.
#[test]
fn shaped_ringing_after_a_corner_is_v_times_the_unshaped() {
    let f = 40.0;
    let omega = 2.0 * PI * f;
    let v = 100.0;
    let accel = v * f / 2.0; // v/a = 2/f: two periods
    let l = limits(v, accel, v);
    let p = plan(&[[0.0, 0.0], [60.0, 0.0], [60.0, 60.0]], &l).unwrap();
    assert!((p.segments[0].v_end - v).abs() < 1e-9);
    let xp = plant(f, 0.0);
    let yp = plant(55.0, 0.05);
    let run = |shaper: Option<&Shaper>| {
        corner(
            &p,
            [
                Axis { plant: &xp, shaper },
                Axis {
                    plant: &yp,
                    shaper: None,
                },
            ],
            1.0 / (f * 400.0),
            0.0,
        )
        .unwrap()
    };
    let unshaped = run(None);
    let c = unshaped.corners[0];
    assert!((c.time - p.segments[1].t_start).abs() < 1e-12);
    assert!(c.window_s > 3.0 / f, "{}", c.window_s);
    let expected = v / omega;
    assert!(
        (c.ringing - expected).abs() < 1e-3 * expected,
        "{} vs {expected}",
        c.ringing
    );
    for shaper in [
        zv(&Mode::new(44.0, 0.0).unwrap()).unwrap(),
        zvd(&Mode::new(48.0, 0.0).unwrap()).unwrap(),
    ] {
        let vib = residual_vibration(&shaper, &Mode::new(f, 0.0).unwrap());
        assert!(vib > 0.05, "the mismatch leaves some vibration: {vib}");
        let shaped = run(Some(&shaper)).corners[0];
        assert!(
            (shaped.ringing - vib * expected).abs() < 1e-3 * expected,
            "{} vs V·v/ω = {}",
            shaped.ringing,
            vib * expected
        );
        assert!(shaped.ringing < c.ringing);
    }
}

#[test]
fn bad_paths_and_limits_are_named() {
    let l = limits(100.0, 1000.0, 5.0);
    let field = |e: Error| e.field().map(str::to_owned);
    assert_eq!(
        field(plan(&[[0.0, 0.0]], &l).unwrap_err()).as_deref(),
        Some("points")
    );
    assert_eq!(
        field(plan(&[[0.0, 0.0], [f64::NAN, 1.0]], &l).unwrap_err()).as_deref(),
        Some("points[1][0]")
    );
    assert_eq!(
        field(plan(&[[1.0, 1.0], [1.0, 1.0]], &l).unwrap_err()).as_deref(),
        Some("points")
    );
    assert_eq!(
        field(plan(&[[0.0, 0.0], [1.0, 0.0]], &limits(100.0, 0.0, 5.0)).unwrap_err()).as_deref(),
        Some("accel")
    );
    assert_eq!(
        field(plan(&[[0.0, 0.0], [1.0, 0.0]], &limits(100.0, 10.0, -1.0)).unwrap_err()).as_deref(),
        Some("squareCornerVelocity")
    );
    assert_eq!(field(square(0.0).unwrap_err()).as_deref(), Some("sideMm"));
    assert_eq!(
        field(ringing_tower(120.0, 0.0).unwrap_err()).as_deref(),
        Some("thicknessMm")
    );
    assert_eq!(
        field(ringing_tower(8.0, 8.0).unwrap_err()).as_deref(),
        Some("thicknessMm")
    );
}

/// Klipper's ringing tower (docs/prints/ringing_tower.stl): an L of two 120 mm walls, 8 mm
/// thick. Its outline turns by 90° five times to the left and once to the right (the inner
/// corner); every corner is taken at square_corner_velocity; a wall along Y shows only X's
/// ringing and a wall along X only Y's ("ringing of X axis shows *along* Y axis",
/// docs/Resonance_Compensation.md); and the ringing on the long inner Y wall repeats every V/f
/// mm, the relation Klipper's guide measures the frequency by ("ringing frequency = V·N/D").
#[test]
fn the_ringing_tower_rings_each_wall_with_one_axis() {
    let pts = ringing_tower(120.0, 8.0).unwrap();
    assert_eq!(pts.first(), pts.last());
    let p = plan(&pts, &limits(100.0, 3000.0, 5.0)).unwrap();
    assert_eq!(p.segments.len(), 6);
    let turns: Vec<f64> = p
        .segments
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0].direction, w[1].direction);
            a[0] * b[1] - a[1] * b[0]
        })
        .collect();
    assert_eq!(turns, [1.0, 1.0, -1.0, 1.0, 1.0]);
    for w in p.segments.windows(2) {
        assert!((w[0].v_end - 5.0).abs() < 1e-9, "{}", w[0].v_end);
    }
    let (f, zeta) = (40.0, 0.01);
    let ringing = plant(f, zeta);
    let rigid = ModalPlant::new(vec![Mode::new(f, zeta).unwrap()], vec![0.0]).unwrap();
    let run = |x: &ModalPlant, y: &ModalPlant| {
        corner(
            &p,
            [
                Axis {
                    plant: x,
                    shaper: None,
                },
                Axis {
                    plant: y,
                    shaper: None,
                },
            ],
            1e-4,
            0.0,
        )
        .unwrap()
    };
    // Walls after corners 0..5 run along +Y, −X, +Y, −X, −Y.
    let along_y = [true, false, true, false, true];
    for (x, y, x_rings) in [(&ringing, &rigid, true), (&rigid, &ringing, false)] {
        let print = run(x, y);
        for (c, &wall_along_y) in print.corners.iter().zip(&along_y) {
            if wall_along_y == x_rings {
                assert!(c.peak_deviation > 1e-3, "{c:?}");
            } else {
                assert!(c.peak_deviation < 1e-9, "{c:?}");
            }
        }
    }
    // X ringing on the inner Y wall (segment 3, x = 8): spatial period V/f_d while cruising.
    let print = run(&ringing, &rigid);
    let wall = p.segments[3];
    let (t0, t1) = (wall.t_start + wall.t_accel, wall.t_decel_start());
    let mut crossings = Vec::new();
    for i in 1..print.time.len() {
        let (ta, tb) = (print.time[i - 1], print.time[i]);
        if ta < t0 || tb > t1 {
            continue;
        }
        let (da, db) = (print.nozzle[0][i - 1] - 8.0, print.nozzle[0][i] - 8.0);
        if da * db < 0.0 {
            let s = da / (da - db);
            crossings
                .push(print.nozzle[1][i - 1] + s * (print.nozzle[1][i] - print.nozzle[1][i - 1]));
        }
    }
    assert!(crossings.len() > 20, "{}", crossings.len());
    let half = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let expected = 100.0 / (f * (1.0 - zeta * zeta).sqrt());
    assert!(
        (2.0 * half - expected).abs() < 1e-3 * expected,
        "{} mm vs V/f_d = {expected} mm",
        2.0 * half
    );
}

/// The JSON spec (what `simulateCorner` takes): the same prints as the core calls, the shaped
/// print only when an axis has a shaper, the magnified track through the nozzle at ×1, and each
/// bad field named from the spec's root.
#[test]
fn the_corner_spec_is_the_core_calls() {
    use input_shaping::scenario::{corner_for, CornerSpec};
    let spec = |text: &str| -> CornerSpec { serde_json::from_str(text).unwrap() };
    let base = r#""path":{"kind":"square","sideMm":30},"velocity":120,"accel":4000,
        "x":{"modes":[{"frequencyHz":42,"damping":0.06}],"shaper":{"family":"zvd"}},
        "y":{"modes":[{"frequencyHz":55,"damping":0.05}]},"samplePeriodS":0.0002"#;
    let r = corner_for(&spec(&format!("{{{base},\"magnify\":1}}"))).unwrap();
    let p = plan(&square(30.0).unwrap(), &limits(120.0, 4000.0, 5.0)).unwrap();
    assert_eq!(r.segments, p.segments);
    let (xp, yp) = (plant(42.0, 0.06), plant(55.0, 0.05));
    let sx = zvd(&Mode::new(42.0, 0.06).unwrap()).unwrap();
    fn axes<'a>(x: &'a ModalPlant, y: &'a ModalPlant, s: Option<&'a Shaper>) -> [Axis<'a>; 2] {
        [
            Axis {
                plant: x,
                shaper: s,
            },
            Axis {
                plant: y,
                shaper: None,
            },
        ]
    }
    let unshaped = corner(&p, axes(&xp, &yp, None), 2e-4, 0.05).unwrap();
    let shaped = corner(&p, axes(&xp, &yp, Some(&sx)), 2e-4, 0.05).unwrap();
    assert_eq!(r.unshaped.print, unshaped);
    assert_eq!(r.shaped.as_ref().unwrap().print, shaped);
    assert!(r.shaper_y.is_none() && r.shaper_x.is_some());
    let drawn = r.unshaped.drawn.as_ref().unwrap();
    for (track, nozzle) in drawn.iter().zip(&unshaped.nozzle) {
        for (d, n) in track.iter().zip(nozzle) {
            assert!((d - n).abs() < 1e-9);
        }
    }
    // ×k moves each drawn point k times as far from the path: its distance is k·|deviation|.
    let r10 = corner_for(&spec(&format!("{{{base},\"magnify\":10}}"))).unwrap();
    let d10 = r10.unshaped.drawn.unwrap();
    let i = unshaped
        .deviation
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .unwrap()
        .0;
    let foot_offset = |k: f64, d: &[Vec<f64>; 2]| {
        ((d[0][i] - unshaped.nozzle[0][i]).hypot(d[1][i] - unshaped.nozzle[1][i])) / (k - 1.0)
    };
    assert!(
        (foot_offset(10.0, &d10) - unshaped.deviation[i].abs()).abs() < 1e-9,
        "{} vs {}",
        foot_offset(10.0, &d10),
        unshaped.deviation[i]
    );
    assert!(r10.unshaped.print.corners.len() == 3 && r.unshaped.drawn.is_some());
    let plain = corner_for(&spec(
        r#"{"path":{"kind":"ringingTower"},"velocity":100,"accel":3000,
        "x":{"modes":[{"frequencyHz":42}]},"y":{"modes":[{"frequencyHz":55}]}}"#,
    ))
    .unwrap();
    assert!(plain.shaped.is_none() && plain.unshaped.drawn.is_none());
    assert_eq!(plain.unshaped.print.corners.len(), 5);
    assert!(plain.sample_period_s <= 1.0 / (25.0 * 55.0) + 1e-15);
    let field = |text: &str| {
        corner_for(&spec(text))
            .unwrap_err()
            .field()
            .map(str::to_owned)
    };
    let axes_ok = r#""x":{"modes":[{"frequencyHz":42}]},"y":{"modes":[{"frequencyHz":55}]}"#;
    for (bad, name) in [
        (
            format!(r#"{{"path":{{"kind":"square","sideMm":0}},"velocity":1,"accel":1,{axes_ok}}}"#),
            "path.sideMm",
        ),
        (
            format!(r#"{{"path":{{"kind":"ringingTower","thicknessMm":130}},"velocity":1,"accel":1,{axes_ok}}}"#),
            "path.thicknessMm",
        ),
        (
            format!(r#"{{"path":{{"kind":"square","sideMm":9}},"velocity":0,"accel":1,{axes_ok}}}"#),
            "velocity",
        ),
        (
            format!(r#"{{"path":{{"kind":"square","sideMm":9}},"velocity":1,"accel":1,"squareCornerVelocity":-1,{axes_ok}}}"#),
            "squareCornerVelocity",
        ),
        (
            r#"{"path":{"kind":"square","sideMm":9},"velocity":1,"accel":1,"x":{"modes":[{"frequencyHz":-1}]},"y":{"modes":[{"frequencyHz":55}]}}"#.to_string(),
            "x.modes[0].frequencyHz",
        ),
        (
            r#"{"path":{"kind":"square","sideMm":9},"velocity":1,"accel":1,"x":{"modes":[{"frequencyHz":42}]},"y":{"modes":[{"frequencyHz":55}],"shaper":{"family":"ei","vtol":2}}}"#.to_string(),
            "y.shaper.vtol",
        ),
        (
            format!(r#"{{"path":{{"kind":"square","sideMm":9}},"velocity":1,"accel":1,{axes_ok},"samplePeriodS":1e-9}}"#),
            "samplePeriodS",
        ),
        (
            format!(r#"{{"path":{{"kind":"square","sideMm":9}},"velocity":1,"accel":1,{axes_ok},"settleS":-1}}"#),
            "settleS",
        ),
        (
            format!(r#"{{"path":{{"kind":"square","sideMm":9}},"velocity":1,"accel":1,{axes_ok},"magnify":0}}"#),
            "magnify",
        ),
    ] {
        assert_eq!(field(&bad).as_deref(), Some(name), "{bad}");
    }
}
