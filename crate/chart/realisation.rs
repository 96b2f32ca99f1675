//! The realisation chart: V (in %) against frequency for each compared shaper as designed
//! (solid) and as its controller runs it (dashed, same colour), with Vtol and the modes marked
//! ([`crate::realise`]).

use super::{render_error, ChartStyle, Key};
use crate::error::Result;
use crate::vibration::SensitivityCurve;
use plotters::coord::Shift;
use plotters::prelude::*;

/// One compared shaper: its label, its designed curve and its realised curve.
pub type RealisedCurves<'a> = (&'a str, &'a SensitivityCurve, &'a SensitivityCurve);

/// Draws each shaper's designed V(f) solid and its realised V(f) dashed in the same colour, a
/// horizontal line at `vtol` (fraction) and a vertical marker at each frequency in `modes_hz`.
/// The legend names the realised curve `"<label>, realised"`.
pub fn draw_realisation<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    curves: &[RealisedCurves<'_>],
    vtol: Option<f64>,
    modes_hz: &[f64],
    style: &ChartStyle,
) -> Result<()> {
    area.fill(&WHITE).map_err(render_error)?;
    let all = || curves.iter().flat_map(|(_, a, b)| [*a, *b]);
    let (f_lo, f_hi) = super::finite_range(
        all().flat_map(|c| c.frequency_hz.iter().copied()),
        (0.0, 1.0),
    );
    let vtol = super::drawable_vtol(vtol);
    let v_max = super::curves::v_axis_max(all().flat_map(|c| c.vibration.iter().copied()), vtol);
    let mut chart = super::framed(area, "V(f) designed and as run", 52.0, style)
        .build_cartesian_2d(f_lo..f_hi, 0.0..v_max)
        .map_err(render_error)?;
    super::mesh(&mut chart, "frequency (Hz)", "vibration (%)", style)
        .draw()
        .map_err(render_error)?;
    let mut keys =
        super::curves::marks_and_vtol(&mut chart, modes_hz, vtol, (f_lo, f_hi), v_max, style)?;
    let points = |c: &SensitivityCurve| -> Vec<(f64, f64)> {
        c.frequency_hz
            .iter()
            .zip(&c.vibration)
            .filter(|(f, v)| f.is_finite() && v.is_finite())
            .map(|(&f, &v)| {
                (
                    super::clip(f, f_lo, f_hi),
                    super::clip(v * 100.0, 0.0, v_max),
                )
            })
            .collect()
    };
    for (k, (label, ideal, realised)) in curves.iter().enumerate() {
        let color = style.color(k);
        chart
            .draw_series(LineSeries::new(
                points(ideal),
                color.stroke_width(style.px(2.0)),
            ))
            .map_err(render_error)?;
        let dash = style.px(6.0);
        chart
            .draw_series(DashedLineSeries::new(
                points(realised),
                dash,
                dash,
                color.stroke_width(style.px(2.0)),
            ))
            .map_err(render_error)?;
        keys.push(label.to_string(), Key::line(color.stroke_width(3)));
        keys.push(
            format!("{label}, realised"),
            Key::line(color.mix(0.6).stroke_width(1)),
        );
    }
    keys.draw_default(&chart, SeriesLabelPosition::UpperRight, style)?;
    area.present().map_err(render_error)?;
    Ok(())
}
