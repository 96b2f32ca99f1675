//! The cost of a realisation: V at each mode, I(Vtol) before and after, the frequency the
//! realised shaper acts at, and the one-line summary.

use super::{fmt_hz, Change, ModeVibration, Realisation, RealiseOptions};
use crate::design::DesignRequest;
use crate::error::Result;
use crate::mode::Mode;
use crate::shaper::Shaper;
use crate::vibration::{insensitivity, residual_vibration, sensitivity};

/// Largest misfit, as a fraction of the ideal duration, between the realised times and the
/// ideal ones scaled by one factor, for the realised shaper to be said to "act as" another
/// frequency.
const SCALE_FIT: f64 = 0.02;

/// Assembles the [`Realisation`].
pub(super) fn build(
    request: &DesignRequest,
    modes: &[Mode],
    ideal: Shaper,
    realised: Shaper,
    runs: String,
    changes: Vec<Change>,
    options: &RealiseOptions,
) -> Result<Realisation> {
    let first = &modes[0];
    let insensitivity_ideal = insensitivity(&ideal, first, options.vtol)?;
    let insensitivity_realised = insensitivity(&realised, first, options.vtol)?;
    let per_mode: Vec<ModeVibration> = modes
        .iter()
        .map(|m| ModeVibration {
            frequency_hz: m.frequency_hz(),
            damping: m.damping(),
            vibration_ideal: residual_vibration(&ideal, m),
            vibration_realised: residual_vibration(&realised, m),
        })
        .collect();
    let acts_as_hz = time_scale(&ideal, &realised).map(|s| first.frequency_hz() / s);
    let curve = |shaper: &Shaper| {
        options
            .curve
            .map(|c| sensitivity(shaper, &super::sensitivity_options(c, first.damping())))
            .transpose()
            .map_err(|e| e.within("curve"))
    };
    let sensitivity_ideal = curve(&ideal)?;
    let sensitivity_realised = curve(&realised)?;
    let summary = summary_for(
        &changes,
        request.shaper.name(),
        first.frequency_hz(),
        acts_as_hz,
        &per_mode,
    );
    Ok(Realisation {
        firmware: options.firmware,
        ideal: ideal.to_data(),
        realised: realised.to_data(),
        runs,
        changes,
        summary,
        modes: per_mode,
        vtol: options.vtol,
        insensitivity_ideal,
        insensitivity_realised,
        acts_as_hz,
        sensitivity_ideal,
        sensitivity_realised,
    })
}

/// The factor s with realised times ≈ s · ideal times (the ratio of durations), when the two
/// have as many impulses, every time fits within [`SCALE_FIT`] of the duration, and s differs
/// from 1 by more than 10⁻⁹.
fn time_scale(ideal: &Shaper, realised: &Shaper) -> Option<f64> {
    let (a, b) = (ideal.impulses(), realised.impulses());
    if a.len() != b.len() || ideal.duration() <= 0.0 || realised.duration() <= 0.0 {
        return None;
    }
    let s = realised.duration() / ideal.duration();
    let fits = a
        .iter()
        .zip(b)
        .all(|(x, y)| (y.time - s * x.time).abs() <= SCALE_FIT * realised.duration());
    (fits && (s - 1.0).abs() > 1e-9).then_some(s)
}

/// The one-line summary: the changes joined, then what they cost, e.g. "times rounded to
/// 1 ms: the 60 Hz ZV acts as a 62.5 Hz one, V = 6.3 % at the mode".
pub fn summary_for(
    changes: &[Change],
    family: &str,
    frequency_hz: f64,
    acts_as_hz: Option<f64>,
    modes: &[ModeVibration],
) -> String {
    let at = if modes.len() == 1 {
        format!("V = {} at the mode", percent(modes[0].vibration_realised))
    } else {
        let list: Vec<String> = modes
            .iter()
            .map(|m| {
                format!(
                    "{} at {} Hz",
                    percent(m.vibration_realised),
                    fmt_hz(m.frequency_hz)
                )
            })
            .collect();
        format!("V = {}", list.join(", "))
    };
    if changes.is_empty() {
        return format!("runs as designed: {at}");
    }
    let what: Vec<&str> = changes.iter().map(|c| c.text.as_str()).collect();
    let cost = match acts_as_hz {
        Some(f) => format!(
            "the {} Hz {} acts as a {} Hz one, {at}",
            fmt_hz(frequency_hz),
            family.to_uppercase(),
            fmt_hz(f)
        ),
        None => at,
    };
    format!("{}: {cost}", what.join("; "))
}

/// A fraction as a percentage with one decimal ("6.3 %"), or two below 1 %.
fn percent(v: f64) -> String {
    if v < 0.01 {
        format!("{:.2} %", v * 100.0)
    } else {
        format!("{:.1} %", v * 100.0)
    }
}
