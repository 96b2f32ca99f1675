//! The impulse-sequence chart: each impulse as a stem from 0 to its amplitude at its time.

use super::{render_error, ChartStyle, Key, Legend};
use crate::error::Result;
use crate::shaper::{Impulse, Shaper};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Draws the impulse sequences of one or more labelled shapers (overlaid, one colour each).
pub fn draw_impulses<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    shapers: &[(&str, &Shaper)],
    style: &ChartStyle,
) -> Result<()> {
    area.fill(&WHITE).map_err(render_error)?;
    let t_max = shapers
        .iter()
        .map(|(_, s)| s.duration())
        .fold(0.0_f64, f64::max);
    let t_max = if t_max > 0.0 {
        t_max.min(super::AXIS_LIMIT)
    } else {
        1.0
    };
    let (a_min, a_max) = shapers
        .iter()
        .flat_map(|(_, s)| s.impulses().iter().map(|imp| imp.amplitude))
        .map(|a| a.clamp(-super::AXIS_LIMIT, super::AXIS_LIMIT))
        .fold((0.0_f64, 0.0_f64), |(lo, hi), a| (lo.min(a), hi.max(a)));
    let pad = 0.12 * (a_max - a_min).max(1e-9);
    let x_pad = 0.06 * t_max;
    let mut chart = super::framed(area, "Impulse sequence", 52.0, style)
        .build_cartesian_2d(-x_pad..t_max + x_pad, (a_min - pad).min(0.0)..a_max + pad)
        .map_err(render_error)?;
    super::mesh(&mut chart, "time (s)", "amplitude", style)
        .draw()
        .map_err(render_error)?;
    chart
        .draw_series(LineSeries::new(
            [(-x_pad, 0.0), (t_max + x_pad, 0.0)],
            BLACK.stroke_width(style.px(1.0)),
        ))
        .map_err(render_error)?;
    let mut keys = Legend::default();
    let n = shapers.len().max(1) as f64;
    for (k, (label, shaper)) in shapers.iter().enumerate() {
        let color = style.color(k);
        // Offset overlaid series slightly so coincident stems stay visible.
        let dx = if n > 1.0 {
            (k as f64 - (n - 1.0) / 2.0) * 0.012 * t_max
        } else {
            0.0
        };
        let stroke = color.stroke_width(style.px(2.5));
        let (drawn, every) = drawn_impulses(shaper.impulses());
        chart
            .draw_series(drawn.iter().map(|imp| {
                PathElement::new(
                    vec![
                        (imp.time.min(t_max) + dx, 0.0),
                        (
                            imp.time.min(t_max) + dx,
                            super::clip(imp.amplitude, a_min, a_max),
                        ),
                    ],
                    stroke,
                )
            }))
            .map_err(render_error)?;
        keys.push(label.to_string(), Key::line(color.stroke_width(3)));
        let r = style.px(4.0);
        // A decimated sequence's stems touch: its heads would be a solid band, so left out.
        let heads = if every { drawn.as_slice() } else { &[] };
        chart
            .draw_series(heads.iter().map(|imp| {
                let at = (
                    imp.time.min(t_max) + dx,
                    super::clip(imp.amplitude, a_min, a_max),
                );
                Circle::new(at, r, color.filled())
            }))
            .map_err(render_error)?;
    }
    if shapers.len() > 1 {
        keys.draw_default(&chart, SeriesLabelPosition::UpperRight, style)?;
    }
    area.present().map_err(render_error)?;
    Ok(())
}

/// Most impulses drawn one by one; a longer sequence (a convolution over many modes, up to
/// 5⁶ = 15 625 impulses) is drawn as its envelope at [`ENVELOPE_BINS`] times.
const MAX_DRAWN_IMPULSES: usize = 1024;
/// Time bins of a long sequence's envelope: more than a chart has pixel columns.
const ENVELOPE_BINS: usize = 2048;

/// The impulses to draw and whether they are all of them: up to [`MAX_DRAWN_IMPULSES`], every
/// impulse; beyond, per time bin (of [`ENVELOPE_BINS`] over the duration) the largest positive
/// and the most negative impulse, which at a chart's resolution (fewer pixel columns than
/// bins) draw the same stems.
fn drawn_impulses(impulses: &[Impulse]) -> (Vec<Impulse>, bool) {
    if impulses.len() <= MAX_DRAWN_IMPULSES {
        return (impulses.to_vec(), true);
    }
    let end = impulses
        .last()
        .map_or(0.0, |imp| imp.time)
        .max(f64::MIN_POSITIVE);
    let mut bins: Vec<[Option<Impulse>; 2]> = vec![[None, None]; ENVELOPE_BINS];
    for imp in impulses {
        let k = ((imp.time / end * (ENVELOPE_BINS - 1) as f64) as usize).min(ENVELOPE_BINS - 1);
        let side = usize::from(imp.amplitude < 0.0);
        let slot = &mut bins[k][side];
        if slot.is_none_or(|s| imp.amplitude.abs() > s.amplitude.abs()) {
            *slot = Some(*imp);
        }
    }
    (bins.into_iter().flatten().flatten().collect(), false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_sequence_is_drawn_as_its_envelope() {
        // 10 000 impulses alternating in sign, amplitude growing with k: every bin's largest
        // positive and most negative one are kept, and so the sequence's extremes.
        let imps: Vec<Impulse> = (0..10000)
            .map(|k| Impulse {
                time: k as f64 * 1e-3,
                amplitude: if k % 2 == 0 { 1.0 } else { -1.0 } * (1.0 + k as f64),
            })
            .collect();
        let (drawn, every) = drawn_impulses(&imps);
        assert!(!every && drawn.len() <= 2 * ENVELOPE_BINS && drawn.len() < imps.len());
        assert!(drawn.iter().any(|i| i.amplitude == -10000.0));
        assert!(drawn.iter().any(|i| i.amplitude == 9999.0));
        // Each kept impulse is the largest of its sign within its bin.
        let bin =
            |t: f64| ((t / 9.999 * (ENVELOPE_BINS - 1) as f64) as usize).min(ENVELOPE_BINS - 1);
        for d in &drawn {
            let beaten = imps.iter().any(|i| {
                bin(i.time) == bin(d.time)
                    && (i.amplitude < 0.0) == (d.amplitude < 0.0)
                    && i.amplitude.abs() > d.amplitude.abs()
            });
            assert!(!beaten, "{d:?}");
        }
        let short = &imps[..100];
        assert_eq!(drawn_impulses(short), (short.to_vec(), true));
    }
}
