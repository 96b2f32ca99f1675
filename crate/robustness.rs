//! Robustness against duration, family by family (Singhose 2009 Fig. 11).
//!
//! A robust shaper buys insensitivity to modelling errors with duration: ZV lasts half a period
//! and keeps V ≤ 5 % over a 6 % band of frequencies, ZVD lasts a period and covers 29 %, and so
//! on (Singhose 2009 §3.1, Figs. 7 and 11). [`robustness_table`] designs each requested family
//! for one mode and lists its duration in periods next to its insensitivities, so families —
//! including ones added later — can be compared on the same axes as Fig. 11.

use crate::design::direct::DirectSpec;
use crate::design::extra_insensitive::DEFAULT_VTOL;
#[cfg(doc)]
use crate::design::FAMILIES;
use crate::design::{design_for, ShaperSpec};
use crate::error::{count, Error, Result};
use crate::mode::Mode;
use crate::vibration::{damping_insensitivity, insensitivity, tolerable_vibration};
use serde::Serialize;

/// Most rows (specs) one table may have.
pub const MAX_TABLE_ROWS: usize = 64;

/// One family's point on the robustness–duration chart.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct RobustnessRow {
    /// The spec the shaper was designed from (family and parameters).
    pub spec: ShaperSpec,
    /// The family's human name (from [`FAMILIES`]).
    pub title: String,
    /// Number of impulses.
    pub impulses: usize,
    /// Duration (time of the last impulse) in seconds.
    pub duration_s: f64,
    /// Duration in damped periods of the mode, T_d = 2π/ω_d (the horizontal axis of Singhose
    /// 2009 Fig. 11; at ζ = 0 the same as undamped periods).
    pub duration_periods: f64,
    /// Frequency insensitivity I(Vtol): the width of the band around the mode where V ≤ Vtol,
    /// as a fraction of the mode's frequency (the vertical axis of Fig. 11; see
    /// [`crate::vibration::insensitivity`]).
    pub insensitivity: f64,
    /// Width of the damping band around the mode's damping where V ≤ Vtol at the mode's
    /// frequency, in damping ratio (see [`crate::vibration::damping_insensitivity`]).
    pub damping_insensitivity: f64,
}

/// Every family of [`FAMILIES`] that can be designed from its name alone (a spec
/// `{ family }` with no other field parses), in the table's order, each with its parameters'
/// defaults. Families with required parameters (such as `zvdn`'s `derivatives`) are left out;
/// pass them explicitly to [`robustness_table`]. `si` parses without fields but cannot be
/// designed without a band (`insensitivity`, `bandHz` or `sampleFrequenciesHz`), so it is left
/// out too.
///
/// Written out rather than found by parsing `{ family }` for every row: that parse through
/// serde's in-memory deserializer compiled the whole spec parser a second time into the wasm
/// (11 KB gzip). A test parses every row and checks that it yields exactly this list.
pub fn parameterless_specs() -> Vec<ShaperSpec> {
    let vtol = DEFAULT_VTOL;
    vec![
        ShaperSpec::Zv,
        ShaperSpec::Zvd,
        ShaperSpec::Zvdd,
        ShaperSpec::Ei { vtol },
        ShaperSpec::Ei2 { vtol },
        ShaperSpec::Ei3 { vtol },
        ShaperSpec::Mzv,
        ShaperSpec::Umzv,
        ShaperSpec::Umzvd,
        ShaperSpec::Umei { vtol },
        ShaperSpec::Direct(DirectSpec::default()),
    ]
}

/// Designs each of `specs` for `mode` and measures it: duration in periods, frequency
/// insensitivity I(`vtol`) and damping insensitivity (Singhose 2009 Fig. 11 as a table).
///
/// Errors: `vtol` outside (0, 1); more than [`MAX_TABLE_ROWS`] specs; a spec that cannot be
/// designed for the mode (the error is prefixed `specs[i]`).
///
/// ```
/// use input_shaping::{robustness::robustness_table, Mode, ShaperSpec};
/// let rows = robustness_table(&[ShaperSpec::Zv, ShaperSpec::Zvd], &Mode::new(1.0, 0.0)?, 0.05)?;
/// // Undamped ZV: half a period, I(5 %) = 4·asin(0.05)/π; ZVD lasts twice as long, is wider.
/// assert!((rows[0].duration_periods - 0.5).abs() < 1e-12);
/// assert!((rows[0].insensitivity - 4.0 * 0.05_f64.asin() / std::f64::consts::PI).abs() < 1e-9);
/// assert!((rows[1].duration_periods - 1.0).abs() < 1e-12 && rows[1].insensitivity > rows[0].insensitivity);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn robustness_table(
    specs: &[ShaperSpec],
    mode: &Mode,
    vtol: f64,
) -> Result<Vec<RobustnessRow>> {
    tolerable_vibration(vtol)?;
    count("specs", specs.len(), 0, MAX_TABLE_ROWS)?;
    let period = mode.damped_period_s();
    specs
        .iter()
        .enumerate()
        .map(|(i, spec)| {
            let within = |e: Error| e.within(&format!("specs[{i}]"));
            let shaper = design_for(spec, std::slice::from_ref(mode)).map_err(within)?;
            Ok(RobustnessRow {
                spec: spec.clone(),
                title: spec.info().map_or(spec.name(), |f| f.title).to_string(),
                impulses: shaper.len(),
                duration_s: shaper.duration(),
                duration_periods: shaper.duration() / period,
                insensitivity: insensitivity(&shaper, mode, vtol)?.width,
                damping_insensitivity: damping_insensitivity(&shaper, mode, vtol)?.width,
            })
        })
        .collect()
}
