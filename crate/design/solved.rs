//! What the solved families (`si`, `direct`) share before they hand their program to the
//! solver: the checks of the amplitude bounds and the duration cap, with the same fields and
//! messages in both.

use crate::error::{finite, positive, Error, Result};

/// Checks `amplitudeMin` < `amplitudeMax` (> 0), `amplitudeMin` ≤ 1, and `maxDuration` > 0.
pub(crate) fn check_bounds(
    amplitude_min: f64,
    amplitude_max: f64,
    max_duration: Option<f64>,
) -> Result<()> {
    finite("amplitudeMin", amplitude_min)?;
    finite("amplitudeMax", amplitude_max)?;
    if amplitude_max <= 0.0 {
        return Err(Error::invalid(
            "amplitudeMax",
            format!("must be > 0, got {amplitude_max}"),
        ));
    }
    if amplitude_min >= amplitude_max || amplitude_min > 1.0 {
        return Err(Error::invalid(
            "amplitudeMin",
            format!(
                "must be below amplitudeMax ({amplitude_max}) and at most 1, got {amplitude_min}"
            ),
        ));
    }
    if let Some(d) = max_duration {
        positive("maxDuration", d)?;
    }
    Ok(())
}
