//! The playground's simulation, command, spectrum and robustness charts, rendered natively into
//! SVG strings through the same code the page draws on canvas; the assertions read the drawn
//! geometry back (polyline points, circle centres) and compare it with what the core predicts.
#![cfg(not(target_arch = "wasm32"))]

use input_shaping::chart::{
    draw_command, draw_response, draw_robustness, draw_spectrum, ChartStyle, RobustnessMark,
    SERIES_COLORS, UNSHAPED_COLOR,
};
use input_shaping::command::{trapezoid, Command};
use input_shaping::design::zero_vibration::{zv, zvd};
use input_shaping::plant::{ModalPlant, Plant};
use input_shaping::robustness::{parameterless_specs, robustness_table};
use input_shaping::simulate::{simulate, Trajectory};
use input_shaping::spectrum::{command_spectrum, SpectrumOptions, SpectrumSignal};
use input_shaping::vibration::insensitivity;
use input_shaping::Mode;
use plotters::prelude::*;

const W: u32 = 720;
const H: u32 = 480;

fn svg(draw: impl FnOnce(&DrawingArea<SVGBackend, plotters::coord::Shift>)) -> String {
    let mut out = String::new();
    {
        let area = SVGBackend::with_string(&mut out, (W, H)).into_drawing_area();
        draw(&area);
    }
    out
}

/// The texts of an SVG, trimmed.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| t.split_once('>'))
        .map(|(_, rest)| rest.split('<').next().unwrap_or("").trim().to_string())
        .collect()
}

fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

fn attr<'a>(element: &'a str, name: &str) -> Option<&'a str> {
    element
        .split(&format!(" {name}=\""))
        .nth(1)
        .and_then(|r| r.split('"').next())
}

/// The points of every polyline stroked in `color`, in drawing order.
fn polylines(svg: &str, color: RGBColor) -> Vec<Vec<(f64, f64)>> {
    let want = hex(color);
    svg.split("<polyline")
        .skip(1)
        .filter(|e| attr(e, "stroke").is_some_and(|s| s.eq_ignore_ascii_case(&want)))
        .map(|e| {
            attr(e, "points")
                .unwrap_or("")
                .split_whitespace()
                .filter_map(|p| p.split_once(','))
                .map(|(x, y)| (x.parse().unwrap(), y.parse().unwrap()))
                .collect()
        })
        .collect()
}

/// Centres of the circles whose `key` (fill or stroke) is `color`.
fn circles(svg: &str, key: &str, color: RGBColor) -> Vec<(f64, f64)> {
    let want = hex(color);
    svg.split("<circle")
        .skip(1)
        .filter(|e| attr(e, key).is_some_and(|s| s.eq_ignore_ascii_case(&want)))
        .map(|e| {
            (
                attr(e, "cx").unwrap().parse().unwrap(),
                attr(e, "cy").unwrap().parse().unwrap(),
            )
        })
        .collect()
}

fn span(points: &[(f64, f64)]) -> f64 {
    let (lo, hi) = points.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
        (lo.min(p.1), hi.max(p.1))
    });
    hi - lo
}

/// A 2 Hz, ζ = 0.05 modal plant, a trapezoid move, and its unshaped and ZV-shaped responses.
fn moves() -> (Mode, Trajectory, Trajectory, f64) {
    let mode = Mode::new(2.0, 0.05).unwrap();
    let plant = Plant::Modal(ModalPlant::new(vec![mode], vec![1.0]).unwrap());
    let command = Command::Piecewise(trapezoid(1.0, 1.6, 20.0, 0.0).unwrap());
    let shaper = zv(&mode).unwrap();
    let shaped = command.shaped(&shaper).unwrap();
    let end = shaped.end_time();
    let t = 3.0;
    let u = simulate(&plant, &command, t / 1999.0, t).unwrap();
    let s = simulate(&plant, &shaped, t / 1999.0, t).unwrap();
    (mode, u, s, end / t)
}

/// After the shaped move ends, the ZV-shaped deflection is flat (V = 0 at the exact mode,
/// Singhose 2009 eq. 11) while the unshaped one keeps ringing; both panels, the caption and the
/// legend are drawn.
#[test]
fn response_chart_shows_the_shaped_move_settling() {
    let (_, u, s, end_fraction) = moves();
    let out = svg(|a| {
        draw_response(
            a,
            &u,
            &[("ZV", &s)],
            "Simulated response (r = 1)",
            &ChartStyle::default(),
        )
        .unwrap()
    });
    let t = texts(&out);
    for want in [
        "Simulated response (r = 1)",
        "endpoint",
        "deflection",
        "time (s)",
        "unshaped",
        "ZV",
    ] {
        assert!(t.iter().any(|x| x == want), "{want:?} in {t:?}");
    }
    let grey = polylines(&out, UNSHAPED_COLOR);
    let blue = polylines(&out, SERIES_COLORS[0]);
    // Endpoint and deflection series (plus a legend swatch) per colour.
    let series = |lines: &[Vec<(f64, f64)>]| -> Vec<Vec<(f64, f64)>> {
        lines.iter().filter(|l| l.len() > 10).cloned().collect()
    };
    let (grey, blue) = (series(&grey), series(&blue));
    assert_eq!((grey.len(), blue.len()), (2, 2));
    let x0 = blue[1].first().unwrap().0;
    let x1 = blue[1].last().unwrap().0;
    let after = |l: &[(f64, f64)]| -> Vec<(f64, f64)> {
        let cut = x0 + (end_fraction + 0.02) * (x1 - x0);
        l.iter().copied().filter(|p| p.0 > cut).collect()
    };
    let shaped_ring = span(&after(&blue[1]));
    let unshaped_ring = span(&after(&grey[1]));
    assert!(
        shaped_ring <= 1.0,
        "shaped deflection after the move spans {shaped_ring} px"
    );
    assert!(
        unshaped_ring > 20.0,
        "unshaped deflection after the move spans {unshaped_ring} px"
    );
}

/// Three panels (position, velocity, acceleration); the shaped trapezoid ends at the same
/// position as the command, later by the shaper's duration, and its acceleration peak is no
/// higher (a positive shaper averages the command).
#[test]
fn command_chart_draws_position_velocity_and_acceleration() {
    let (_, u, s, _) = moves();
    let out = svg(|a| draw_command(a, &u, &[("ZV", &s)], &ChartStyle::default()).unwrap());
    let t = texts(&out);
    for want in [
        "Command and shaped command",
        "position",
        "velocity",
        "acceleration",
        "time (s)",
        "command",
        "ZV",
    ] {
        assert!(t.iter().any(|x| x == want), "{want:?} in {t:?}");
    }
    let long = |c| -> Vec<Vec<(f64, f64)>> {
        polylines(&out, c)
            .into_iter()
            .filter(|l| l.len() > 10)
            .collect()
    };
    let (grey, blue) = (long(UNSHAPED_COLOR), long(SERIES_COLORS[0]));
    assert_eq!((grey.len(), blue.len()), (3, 3));
    let (gp, bp) = (&grey[0], &blue[0]);
    assert!(
        (gp.last().unwrap().1 - bp.last().unwrap().1).abs() < 0.5,
        "same final position"
    );
    // Panel-relative heights of the acceleration: the command's spans its panel, the shaped
    // one (the command averaged over the ZV pair, same ±a plateaus) no more.
    assert!(span(&blue[2]) <= span(&grey[2]) + 0.5);
    // The shaped position reaches the final value later.
    let reach = |l: &[(f64, f64)]| {
        let last = l.last().unwrap().1;
        l.iter().find(|p| (p.1 - last).abs() < 0.5).unwrap().0
    };
    assert!(
        reach(bp) > reach(gp) + 5.0,
        "{} vs {}",
        reach(bp),
        reach(gp)
    );
}

/// A ZV-shaped trapezoid has no velocity content at the mode: the shaped curve touches zero at
/// the marked mode (within a pixel column), the unshaped one does not.
#[test]
fn spectrum_chart_marks_the_modes_and_the_shaped_zero() {
    let mode = Mode::new(2.0, 0.0).unwrap();
    let command = Command::Piecewise(trapezoid(1.0, 1.6, 20.0, 0.0).unwrap());
    let shaped = command.shaped(&zv(&mode).unwrap()).unwrap();
    let options = SpectrumOptions {
        from_hz: 0.0,
        to_hz: 6.0,
        points: 601,
        signal: SpectrumSignal::Velocity,
    };
    let u = command_spectrum(&command, &options).unwrap();
    let s = command_spectrum(&shaped, &options).unwrap();
    let out = svg(|a| {
        draw_spectrum(
            a,
            &u.frequency_hz,
            &u.magnitude,
            &[("ZV", &s.magnitude)],
            &[2.0],
            &[2.4],
            &ChartStyle::default(),
        )
        .unwrap()
    });
    let t = texts(&out);
    for want in [
        "Command spectrum |U(f)| (velocity)",
        "frequency (Hz)",
        "|U(f)|",
        "unshaped",
        "ZV",
        "model modes",
        "actual modes",
    ] {
        assert!(t.iter().any(|x| x == want), "{want:?} in {t:?}");
    }
    let marker = polylines(&out, RGBColor(90, 90, 90));
    let mode_x = marker
        .iter()
        .find(|l| l.len() == 2 && l[0].0 == l[1].0)
        .unwrap()[0]
        .0;
    let blue: Vec<(f64, f64)> = polylines(&out, SERIES_COLORS[0])
        .into_iter()
        .max_by_key(|l| l.len())
        .unwrap();
    let grey: Vec<(f64, f64)> = polylines(&out, UNSHAPED_COLOR)
        .into_iter()
        .max_by_key(|l| l.len())
        .unwrap();
    let near = |l: &[(f64, f64)]| {
        l.iter()
            .filter(|p| (p.0 - mode_x).abs() < 1.5)
            .map(|p| p.1)
            .fold(f64::MIN, f64::max)
    };
    let bottom = grey.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    assert!(
        near(&blue) >= bottom - 1.0,
        "shaped touches 0 at the mode: {} vs axis {}",
        near(&blue),
        bottom
    );
    assert!(
        near(&grey) < bottom - 20.0,
        "the unshaped command has content there"
    );
    // The dashed actual-mode marker is drawn (in pieces).
    assert!(polylines(&out, RGBColor(200, 30, 30)).len() > 3);
}

/// The families of Singhose 2009 Fig. 11 are named without overlapping, and a compared ZVD
/// designed for the same mode is ringed exactly on the ZVD family's point.
#[test]
fn robustness_chart_marks_the_chosen_shapers_on_the_families() {
    let mode = Mode::new(1.0, 0.0).unwrap();
    let rows = robustness_table(&parameterless_specs(), &mode, 0.05).unwrap();
    let s = zvd(&mode).unwrap();
    let mark = RobustnessMark {
        label: "ZVD",
        duration_periods: s.duration() / mode.damped_period_s(),
        insensitivity: insensitivity(&s, &mode, 0.05).unwrap().width,
    };
    let out = svg(|a| draw_robustness(a, &rows, &[mark], 0.05, &ChartStyle::default()).unwrap());
    let t = texts(&out);
    for want in [
        "ZV",
        "ZVD",
        "ZVDD",
        "EI",
        "Two-hump EI",
        "duration (damped periods of mode 1)",
        "insensitivity I(Vtol)",
    ] {
        assert!(t.iter().any(|x| x == want), "{want:?} in {t:?}");
    }
    assert!(
        t.iter().any(|x| x.starts_with("Robustness vs duration")),
        "{t:?}"
    );
    let dots = circles(&out, "fill", RGBColor(120, 120, 120));
    assert!(
        dots.len() > rows.len() - 1,
        "{} dots for {} rows",
        dots.len(),
        rows.len()
    );
    let rings = circles(&out, "stroke", SERIES_COLORS[0]);
    assert!(!rings.is_empty());
    let ring = rings[0];
    assert!(
        dots.iter()
            .any(|d| (d.0 - ring.0).abs() < 0.6 && (d.1 - ring.1).abs() < 0.6),
        "ring {ring:?} on a family point {dots:?}"
    );
    // Label anchors differ pairwise (a crude overlap check: the chart's own placement avoids
    // box overlaps; two names at one spot would be unreadable).
    let anchors: Vec<(String, String)> = out
        .split("<text")
        .skip(1)
        .map(|e| {
            (
                attr(e, "x").unwrap_or("").to_string(),
                attr(e, "y").unwrap_or("").to_string(),
            )
        })
        .collect();
    for (i, a) in anchors.iter().enumerate() {
        assert!(!anchors[i + 1..].contains(a), "two texts at {a:?}");
    }
}

/// The page draws a shaped command's spectrum as |S(f)|·|U(f)| (the shaped command is the
/// convolution of the shaper with the command, so its transform is the product). Checked here
/// against the direct transform of the shaped piecewise command, for a multi-mode shaper.
#[test]
fn shaped_spectrum_is_the_product_of_shaper_and_command_spectra() {
    use input_shaping::design::design_for;
    use input_shaping::design::ShaperSpec;
    use input_shaping::spectrum::impulse_spectrum;
    let modes = [
        Mode::new(1.2, 0.012).unwrap(),
        Mode::new(3.4, 0.013).unwrap(),
    ];
    let spec: ShaperSpec = serde_json::from_str(r#"{"family":"zvd"}"#).unwrap();
    let shaper = design_for(&spec, &modes).unwrap();
    let command =
        Command::Piecewise(input_shaping::command::s_curve(0.5, 0.5, 2.0, 20.0, 0.0).unwrap());
    let options = SpectrumOptions {
        from_hz: 0.0,
        to_hz: 8.0,
        points: 301,
        signal: SpectrumSignal::Velocity,
    };
    let u = command_spectrum(&command, &options).unwrap();
    let s = impulse_spectrum(&shaper, &options).unwrap();
    let direct = command_spectrum(&command.shaped(&shaper).unwrap(), &options).unwrap();
    for j in 0..options.points {
        let product = s.magnitude[j] * u.magnitude[j];
        assert!(
            (product - direct.magnitude[j]).abs() < 1e-9 * u.magnitude[0],
            "f = {}: {product} vs {}",
            u.frequency_hz[j],
            direct.magnitude[j]
        );
    }
}

/// Distance from `p` to the polyline `path`, and the fraction along the nearest segment.
fn to_polyline(path: &[(f64, f64)], p: (f64, f64)) -> (f64, f64) {
    let mut best = (f64::INFINITY, 0.0);
    for w in path.windows(2) {
        let (a, b) = (w[0], w[1]);
        let d = (b.0 - a.0, b.1 - a.1);
        let len2 = d.0 * d.0 + d.1 * d.1;
        let t = (((p.0 - a.0) * d.0 + (p.1 - a.1) * d.1) / len2).clamp(0.0, 1.0);
        let dist = (p.0 - a.0 - t * d.0).hypot(p.1 - a.1 - t * d.1);
        if dist < best.0 {
            best = (dist, t);
        }
    }
    best
}

/// The printed-corner chart: the path with equal scales on X and Y, the unshaped track as far
/// from it (in pixels) as the magnified track is in mm, and the track shaped by exact ZV shapers
/// straight in the middle of every wall, where the unshaped one still rings.
#[test]
fn corner_chart_draws_the_magnified_walls_on_equal_scales() {
    use input_shaping::chart::corner::PATH_COLOR;
    use input_shaping::chart::draw_corner;
    use input_shaping::corner::{corner, plan, square, Axis, MotionLimits};
    let (mx, my) = (
        Mode::new(40.0, 0.02).unwrap(),
        Mode::new(50.0, 0.02).unwrap(),
    );
    let (px, py) = (
        ModalPlant::new(vec![mx], vec![1.0]).unwrap(),
        ModalPlant::new(vec![my], vec![1.0]).unwrap(),
    );
    let (sx, sy) = (zv(&mx).unwrap(), zv(&my).unwrap());
    let points = square(20.0).unwrap();
    let limits = MotionLimits {
        velocity: 100.0,
        accel: 3000.0,
        square_corner_velocity: 5.0,
    };
    let p = plan(&points, &limits).unwrap();
    let print = |x, y| {
        corner(
            &p,
            [
                Axis {
                    plant: &px,
                    shaper: x,
                },
                Axis {
                    plant: &py,
                    shaper: y,
                },
            ],
            2e-4,
            0.02,
        )
        .unwrap()
    };
    let magnify = 20.0;
    let unshaped = print(None, None).magnified(&p, magnify).unwrap();
    let shaped = print(Some(&sx), Some(&sy)).magnified(&p, magnify).unwrap();
    let out = svg(|a| {
        draw_corner(
            a,
            &points,
            Some(&unshaped),
            &[("ZV", &shaped)],
            magnify,
            &ChartStyle::default(),
        )
        .unwrap()
    });
    assert!(
        texts(&out).iter().any(|t| t.contains("×20")),
        "{:?}",
        texts(&out)
    );
    let longest = |c: RGBColor| polylines(&out, c).into_iter().max_by_key(Vec::len).unwrap();
    let path = longest(PATH_COLOR);
    assert_eq!(path.len(), 5);
    let along_x = (path[1].0 - path[0].0).abs();
    let along_y = (path[2].1 - path[1].1).abs();
    assert!(
        along_x > 200.0 && (along_x - along_y).abs() <= 1.0,
        "{along_x} vs {along_y}"
    );
    let scale = along_x / 20.0; // px per mm
                                // The farthest the magnified track gets from the path, in mm, against the drawing.
    let farthest_mm = (0..unshaped[0].len())
        .map(|i| {
            let q = (unshaped[0][i], unshaped[1][i]);
            let pts: Vec<(f64, f64)> = points.iter().map(|p| (p[0], p[1])).collect();
            to_polyline(&pts, q).0
        })
        .fold(0.0, f64::max);
    let grey = longest(UNSHAPED_COLOR);
    let middle = |track: &[(f64, f64)]| {
        track
            .iter()
            .map(|&q| to_polyline(&path, q))
            .filter(|(_, t)| (0.4..=0.6).contains(t))
            .map(|(d, _)| d)
            .fold(0.0, f64::max)
    };
    let farthest_px = grey
        .iter()
        .map(|&q| to_polyline(&path, q).0)
        .fold(0.0, f64::max);
    assert!(farthest_px > 5.0, "{farthest_px}");
    assert!(
        (farthest_px - scale * farthest_mm).abs() < 1.5,
        "{farthest_px} px vs {} px",
        scale * farthest_mm
    );
    let (ringing, straight) = (middle(&grey), middle(&longest(SERIES_COLORS[0])));
    assert!(
        ringing > 3.0 && straight < 0.5,
        "unshaped {ringing} px, ZV {straight} px"
    );
}

/// A track magnified beyond reason (or not finite) still draws: no panic, axes within reach.
#[test]
fn corner_chart_survives_absurd_tracks() {
    use input_shaping::chart::draw_corner;
    let points = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]];
    let wild = [
        vec![0.0, 1e308, -1e308, f64::NAN, f64::INFINITY],
        vec![0.0, -1e308, 1e308, 1.0, 2.0],
    ];
    let out = svg(|a| {
        draw_corner(
            a,
            &points,
            Some(&wild),
            &[("x", &wild)],
            1e300,
            &ChartStyle::default(),
        )
        .unwrap()
    });
    assert!(out.contains("<polyline"));
}
