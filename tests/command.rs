//! Reference commands and shaping them: closed forms of the profiles, exact convolution
//! against direct superposition, the streaming filter against the interpolated signal, and
//! Singer & Seering 1988 Fig. 10 (shaping an arbitrary command).

mod common;

use common::close;
use input_shaping::command::{
    ramp, s_curve, step, trapezoid, Command, Interpolation, Piecewise, Sampled, StreamingShaper,
};
use input_shaping::design::zero_vibration::{zv, zvd};
use input_shaping::metrics::mode_residual_percent;
use input_shaping::plant::ModalPlant;
use input_shaping::{Error, Impulse, Mode, Shaper};
use wasm_bindgen_test::wasm_bindgen_test;

/// Direct evaluation of the jump form, Σ_{τ ≤ t} Σ_k J_k (t − τ)^k / k!, for derivative `d`.
fn direct(p: &Piecewise, t: f64, d: usize) -> f64 {
    let mut s = 0.0;
    for k in p.knots().iter().filter(|k| k.time <= t) {
        for (order, &j) in k.jumps.iter().enumerate().skip(d) {
            let n = order - d;
            let fact: f64 = (1..=n).map(|i| i as f64).product();
            s += j * (t - k.time).powi(n as i32) / fact;
        }
    }
    s
}

/// Trapezoidal velocity: reaches v with slopes ±a, travels exactly D; duration D/v + v/a.
#[wasm_bindgen_test(unsupported = test)]
fn trapezoid_meets_distance_and_limits() {
    let (d, v, a) = (2.0, 0.5, 1.0);
    let p = trapezoid(d, v, a, 0.3).unwrap();
    close(
        p.end_time(),
        0.3 + d / v + v / a,
        1e-12,
        "duration D/v + v/a",
    );
    let end = p.eval(p.end_time() + 1.0);
    close(end[0], d, 1e-12, "final position");
    close(end[1], 0.0, 1e-12, "final velocity");
    let mid = p.eval(0.3 + 0.5 * (d / v + v / a));
    close(mid[1], v, 1e-12, "cruise velocity");
    for i in 0..=400 {
        let t = i as f64 * 0.02;
        let s = p.eval(t);
        assert!(s[1] <= v + 1e-12 && s[2].abs() <= a + 1e-12);
        close(s[0], direct(&p, t, 0), 1e-12, "cursor vs direct jump form");
    }
}

/// Peláez & Singhose 2002 §1: "triangular for a short move where the velocity limit is not
/// reached": peak velocity √(D a), duration 2√(D/a).
#[wasm_bindgen_test(unsupported = test)]
fn short_trapezoid_is_triangular() {
    let (d, v, a) = (0.1, 1.0, 2.0);
    let p = trapezoid(-d, v, a, 0.0).unwrap();
    let tp = (d / a).sqrt();
    close(p.end_time(), 2.0 * tp, 1e-14, "duration 2√(D/a)");
    close(p.eval(tp)[1], -(d * a).sqrt(), 1e-13, "peak velocity √(Da)");
    close(p.eval(10.0)[0], -d, 1e-14, "final position");
}

/// Seven-segment S-curve: total time D/v + v/a + a/j when both limits are reached; jerk ±j,
/// acceleration within ±a, continuous acceleration.
#[wasm_bindgen_test(unsupported = test)]
fn s_curve_closed_form_duration_and_limits() {
    let (d, v, a, j) = (3.0, 1.0, 2.0, 10.0);
    let p = s_curve(d, v, a, j, 0.0).unwrap();
    close(p.end_time(), d / v + v / a + a / j, 1e-12, "duration");
    close(p.eval(20.0)[0], d, 1e-12, "final position");
    assert!(p
        .knots()
        .iter()
        .all(|k| k.jumps[..3].iter().all(|&x| x == 0.0)));
    let mut peak_acc: f64 = 0.0;
    for i in 0..=5000 {
        let s = p.eval(i as f64 * p.end_time() / 5000.0);
        peak_acc = peak_acc.max(s[2].abs());
        assert!(s[1] <= v + 1e-12 && s[3].abs() <= j + 1e-12);
    }
    close(peak_acc, a, 1e-9, "peak acceleration");
    // A short move lowers the peak velocity and still lands exactly.
    for &(d, v, a, j) in &[
        (0.01, 1.0, 2.0, 10.0),
        (0.3, 1.0, 2.0, 10.0),
        (5.0, 1.0, 20.0, 10.0),
    ] {
        let p = s_curve(d, v, a, j, 0.0).unwrap();
        close(p.eval(100.0)[0], d, 1e-10, "short S-curve lands");
        close(p.eval(100.0)[1], 0.0, 1e-12, "short S-curve stops");
        for i in 0..=1000 {
            let s = p.eval(i as f64 * p.end_time() / 1000.0);
            assert!(s[1] <= v + 1e-12 && s[2].abs() <= a + 1e-9);
        }
    }
}

/// Exact shaping: the shaped command equals Σ Aᵢ u(t − tᵢ) evaluated directly.
#[wasm_bindgen_test(unsupported = test)]
fn piecewise_shaping_is_the_convolution() {
    let shaper = zvd(&Mode::new(1.3, 0.07).unwrap()).unwrap();
    for u in [
        s_curve(1.0, 0.8, 3.0, 20.0, 0.1).unwrap(),
        trapezoid(-2.0, 1.0, 4.0, 0.0).unwrap(),
        ramp(0.5, 0.2).unwrap(),
        step(3.0, 0.0).unwrap(),
    ] {
        let s = u.shaped(&shaper).unwrap();
        for i in 0..300 {
            let t = i as f64 * 0.013 + 0.0007;
            let want: f64 = shaper
                .impulses()
                .iter()
                .map(|imp| imp.amplitude * direct(&u, t - imp.time, 0))
                .sum();
            close(s.eval(t)[0], want, 1e-12, "shaped position");
        }
    }
}

/// The streaming filter equals the exact shaped command of the linearly interpolated signal,
/// read at the samples, and block processing equals sample-by-sample processing.
#[wasm_bindgen_test(unsupported = test)]
fn streaming_filter_handles_fractional_delays() {
    let period = 0.01;
    // Impulse times deliberately off the grid.
    let shaper = Shaper::new(vec![
        Impulse {
            time: 0.0,
            amplitude: 0.3,
        },
        Impulse {
            time: 0.0237,
            amplitude: 0.45,
        },
        Impulse {
            time: 0.051,
            amplitude: 0.25,
        },
    ])
    .unwrap();
    // Starts at rest (before t = 0 the filter has seen zeros).
    let values: Vec<f64> = (0..500)
        .map(|k| ((k as f64) * 0.07).sin() + 0.3 * (((k as f64) * 0.31).cos() - 1.0))
        .collect();
    let signal = Sampled::new(period, values.clone(), Interpolation::Linear).unwrap();
    let mut f = StreamingShaper::new(&shaper, period).unwrap();
    let mut g = f.clone();
    let mut block = vec![0.0; values.len()];
    g.process(&values, &mut block);
    for (k, &x) in values.iter().enumerate() {
        let y = f.push(x);
        let t = k as f64 * period;
        let want: f64 = shaper
            .impulses()
            .iter()
            .map(|imp| {
                if t - imp.time < 0.0 {
                    0.0
                } else {
                    imp.amplitude * signal.eval(t - imp.time)
                }
            })
            .sum();
        close(y, want, 1e-12, "streaming vs interpolated convolution");
        close(block[k], y, 1e-12, "block vs push");
    }
    // Taps: each fractional delay is split over two neighbouring samples.
    let taps: Vec<(usize, f64)> = f.taps().collect();
    assert_eq!(
        taps.iter().map(|t| t.0).collect::<Vec<_>>(),
        vec![0, 2, 3, 5, 6]
    );
    close(taps.iter().map(|t| t.1).sum(), 1.0, 1e-15, "taps sum to 1");
}

/// Block processing carries its state across calls of any length.
#[wasm_bindgen_test(unsupported = test)]
fn streaming_blocks_of_any_length_agree() {
    let shaper = zvd(&Mode::new(7.3, 0.02).unwrap()).unwrap();
    let x: Vec<f64> = (0..3000).map(|k| ((k * k) % 17) as f64).collect();
    let mut a = StreamingShaper::new(&shaper, 0.001).unwrap();
    let want: Vec<f64> = x.iter().map(|&v| a.push(v)).collect();
    let mut b = StreamingShaper::new(&shaper, 0.001).unwrap();
    let mut got = vec![0.0; x.len()];
    let mut start = 0;
    for len in [1, 7, 500, 3, 1200, 289, 1000] {
        let end = (start + len).min(x.len());
        b.process(&x[start..end], &mut got[start..end]);
        start = end;
    }
    for (g, w) in got.iter().zip(&want) {
        close(*g, *w, 1e-12, "chunked block processing");
    }
}

/// Singer & Seering 1988 §2.4 and Fig. 10: convolving an arbitrary command (a joystick signal)
/// with a two-impulse sequence gives an input that (i) never exceeds the command's largest
/// value, because the amplitudes are positive and sum to one, and (ii) leaves no vibration at
/// the designed mode once the command is over — while the unshaped command does.
#[wasm_bindgen_test(unsupported = test)]
fn singer_seering_fig10_arbitrary_command() {
    let mode = Mode::new(0.8, 0.05).unwrap();
    let shaper = zv(&mode).unwrap();
    let period = 0.02;
    // A joystick: a few pushes of different lengths, then release.
    let values: Vec<f64> = (0..400)
        .map(|k| {
            let t = k as f64 * period;
            if t < 6.0 {
                (0.8 * t).sin().max(0.0) * 0.7 + 0.3 * (2.3 * t).sin().abs()
            } else {
                0.0
            }
        })
        .collect();
    let joystick = Sampled::new(period, values.clone(), Interpolation::Linear).unwrap();
    let max_in = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let exact = joystick.to_piecewise().unwrap().shaped(&shaper).unwrap();
    let streamed = joystick.shaped(&shaper).unwrap();
    for i in 0..2000 {
        let t = i as f64 * 0.005;
        assert!(exact.eval(t)[0].abs() <= max_in + 1e-12);
    }
    assert!(streamed.values().iter().all(|v| v.abs() <= max_in + 1e-12));
    let plant = ModalPlant::new(vec![mode], vec![1.0]).unwrap();
    // Velocity-command reading: the joystick sets the base's velocity, so its integral is the
    // position command (the move ends at rest when the stick is released).
    let position = joystick.to_piecewise().unwrap().integral().unwrap();
    let unshaped = mode_residual_percent(&plant, &position).unwrap().unwrap()[0];
    let shaped = mode_residual_percent(&plant, &position.shaped(&shaper).unwrap())
        .unwrap()
        .unwrap()[0];
    assert!(
        unshaped > 1.0,
        "the joystick move excites the mode: {unshaped} %"
    );
    assert!(shaped < 1e-9, "shaped: {shaped} %");
    // The streamed (controller) version, read linearly between its samples, is within the
    // interpolation error O((ωT)²).
    let streamed_pos = Command::Sampled(streamed)
        .to_piecewise()
        .unwrap()
        .integral()
        .unwrap();
    let s = mode_residual_percent(&plant, &streamed_pos)
        .unwrap()
        .unwrap()[0];
    assert!(
        s < 0.05 * unshaped,
        "streamed: {s} % vs unshaped {unshaped} %"
    );
}

/// Bad input is a typed error naming the field.
#[wasm_bindgen_test(unsupported = test)]
fn bad_commands_are_rejected() {
    let e = trapezoid(1.0, -1.0, 1.0, 0.0).unwrap_err();
    assert_eq!(e.field(), Some("maxVelocity"));
    assert_eq!(
        s_curve(1.0, 1.0, 1.0, f64::NAN, 0.0).unwrap_err().field(),
        Some("maxJerk")
    );
    assert_eq!(step(1.0, -2.0).unwrap_err().field(), Some("start"));
    assert_eq!(
        Sampled::new(-0.1, vec![1.0], Interpolation::Hold)
            .unwrap_err()
            .field(),
        Some("samplePeriod")
    );
    assert!(matches!(
        Sampled::new(0.1, vec![], Interpolation::Hold).unwrap_err(),
        Error::InvalidInput { .. }
    ));
    // A streaming delay beyond the cap.
    let long = Shaper::new(vec![
        Impulse {
            time: 0.0,
            amplitude: 0.5,
        },
        Impulse {
            time: 1e3,
            amplitude: 0.5,
        },
    ])
    .unwrap();
    assert!(matches!(
        StreamingShaper::new(&long, 1e-6).unwrap_err(),
        Error::TooLarge { .. }
    ));
}
