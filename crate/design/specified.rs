//! Specified-insensitivity (SI) shapers: the shortest shaper keeping V ≤ Vtol over a chosen
//! band of frequencies (and optionally of damping ratios).
//!
//! Singhose 2009 eq. 18 (frequency sampling, after Singer & Seering 1992):
//!
//! Vtol ≥ e^{−ζω_s t_n} √(C(ω_s, ζ)² + S(ω_s, ζ)²),  s = 1 … m,
//!
//! with Σ Aᵢ = 1 (eq. 12), Aᵢ ≥ 0 and t_n minimal (eq. 13). Peláez & Singhose 2002 eqs. 6–7
//! design one for 0.5 Hz, ζ = 0.002, Vtol = 5 %, I = 0.7 from six sampled frequencies.
//! Singhose 2009 Figs. 8–10 show the sampling, SI curves for I = 0.5 and 0.7, and an SI shaper
//! robust over 0.7–1.3 Hz *and* ζ ∈ [0, 0.2]; Fig. 11 shows that SI shapers are the shortest
//! for any insensitivity, with the EI shapers as nodes of the SI curve.
//!
//! Two ways to state the constraints:
//!
//! - **sampled** (`sampleFrequenciesHz`): V ≤ Vtol only at the listed frequencies — the paper's
//!   method, reproduced exactly; between samples V may exceed Vtol (the paper's own shaper
//!   reaches 7.4 % at its band edge);
//! - **whole band** (default): V ≤ Vtol everywhere on the band (and damping range), *verified*
//!   on a dense grid with refined maxima; where a first design exceeds Vtol the offending
//!   points become constraints and the design is repeated (exchange loop, [`crate::solve`]).
//!
//! Weighting (Singhose 2009 §3.1, "the lower frequencies within the suppression zone could be
//! weighted more"): `vtolProfile: [[f₁, v₁], [f₂, v₂], …]` replaces the constant `vtol` by a
//! tolerable level piecewise linear in frequency (constant beyond the ends), so a weight w(f)
//! on a frequency is simply Vtol(f) = Vtol/w(f).
//!
//! Design: [`crate::solve::minimum_duration`] — the globally shortest shaper on a fine time grid
//! (convex program, bisection on the duration), reduced to its few impulses and polished by
//! Newton's method so the result is exact. Amplitude bounds `amplitudeMin`/`amplitudeMax`
//! (default 0 and 1) allow negative shapers.

use crate::design::{DesignRequest, Guarantee, ShaperSpec};
use crate::error::{finite, positive, Error, Result};
use crate::mode::Mode;
use crate::shaper::Shaper;
use crate::solve::{self, Band, Limit, Problem, SolverReport, Tolerance};
use serde::{Deserialize, Serialize};

/// Most sampled frequencies accepted.
pub const MAX_SAMPLES: usize = 200;
/// Largest insensitivity accepted (a band from 0.01 f to 1.99 f).
pub const MAX_INSENSITIVITY: f64 = 1.98;
/// Most impulses a `maxImpulses` may ask for (beyond it the cap means nothing).
pub const MAX_IMPULSES_PARAMETER: usize = 1000;

fn default_vtol() -> f64 {
    0.05
}

fn default_amplitude_max() -> f64 {
    1.0
}

/// Parameters of an SI design (`family: "si"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SiSpec {
    /// Tolerable vibration (fraction, 0 < vtol < 1); default 0.05.
    #[serde(default = "default_vtol")]
    pub vtol: f64,
    /// Insensitivity I: the band is [f(1 − I/2), f(1 + I/2)] around each mode's frequency f.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub insensitivity: Option<f64>,
    /// The band in Hz, `[low, high]` (one mode only; instead of `insensitivity`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub band_hz: Option<[f64; 2]>,
    /// Damping ratios to be robust over, `[low, high]` (default: each mode's own damping).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_range: Option<[f64; 2]>,
    /// Sampled mode: limit V only at these frequencies (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_frequencies_hz: Option<Vec<f64>>,
    /// Frequency-dependent Vtol: `[[frequencyHz, vtol], …]`, piecewise linear; replaces `vtol`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vtol_profile: Option<Vec<[f64; 2]>>,
    /// Smallest amplitude (default 0; negative allows negative impulses).
    #[serde(default)]
    pub amplitude_min: f64,
    /// Largest amplitude (default 1).
    #[serde(default = "default_amplitude_max")]
    pub amplitude_max: f64,
    /// Most impulses accepted: a design needing more is reported infeasible.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_impulses: Option<usize>,
    /// Longest duration accepted, seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_duration: Option<f64>,
}

impl Default for SiSpec {
    fn default() -> Self {
        SiSpec {
            vtol: default_vtol(),
            insensitivity: None,
            band_hz: None,
            damping_range: None,
            sample_frequencies_hz: None,
            vtol_profile: None,
            amplitude_min: 0.0,
            amplitude_max: default_amplitude_max(),
            max_impulses: None,
            max_duration: None,
        }
    }
}

impl SiSpec {
    /// A design request for these parameters (a convenience for Rust callers and tests).
    pub fn request(self, modes: Vec<crate::mode::ModeSpec>) -> DesignRequest {
        DesignRequest {
            modes,
            shaper: ShaperSpec::Si(self),
        }
    }
}

/// Checks a `[low, high]` pair: finite, `low ≤ high` (strictly if `strict`).
fn pair(field: &str, p: [f64; 2], strict: bool) -> Result<(f64, f64)> {
    finite(&format!("{field}[0]"), p[0])?;
    finite(&format!("{field}[1]"), p[1])?;
    if p[1] < p[0] || (strict && p[1] == p[0]) {
        return Err(Error::invalid(
            field,
            format!(
                "needs {}[0] {} {}[1], got [{}, {}]",
                field,
                if strict { "<" } else { "≤" },
                field,
                p[0],
                p[1]
            ),
        ));
    }
    Ok((p[0], p[1]))
}

/// The solver problem an SI spec describes, and the bound its result must meet.
fn problem(spec: &SiSpec, modes: &[Mode]) -> Result<Problem> {
    let tolerance = tolerance(spec)?;
    check_amplitudes_and_limits(spec)?;
    let damping_range = damping_range(spec)?;
    let bands = bands(spec, modes, damping_range)?;
    let mut p = Problem {
        zeros: Vec::new(),
        limits: Vec::new(),
        bands: Vec::new(),
        amplitude_min: spec.amplitude_min,
        amplitude_max: spec.amplitude_max,
        max_duration: spec.max_duration,
    };
    match &spec.sample_frequencies_hz {
        Some(samples) => {
            p.limits = sampled_limits(samples, &bands, damping_range, modes, &tolerance)?;
        }
        None => {
            for (lo, hi, zl, zh) in bands {
                p.bands.push(Band {
                    from_hz: lo,
                    to_hz: hi,
                    damping_from: zl,
                    damping_to: zh,
                    tolerance: tolerance.clone(),
                });
            }
        }
    }
    Ok(p)
}

/// The tolerance: constant `vtol`, or the profile.
fn tolerance(spec: &SiSpec) -> Result<Tolerance> {
    Ok(match &spec.vtol_profile {
        Some(points) => Tolerance::profile(points.iter().map(|p| (p[0], p[1])).collect())?,
        None => {
            positive("vtol", spec.vtol)?;
            if spec.vtol >= 1.0 {
                return Err(Error::invalid(
                    "vtol",
                    format!(
                        "tolerable vibration must be below 1 (100 %), got {}",
                        spec.vtol
                    ),
                ));
            }
            Tolerance::constant(spec.vtol).map_err(|e| match e {
                Error::InvalidInput { reason, .. } => Error::invalid("vtol", reason),
                other => other,
            })?
        }
    })
}

/// Checks the amplitude bounds, `maxDuration` and `maxImpulses`.
fn check_amplitudes_and_limits(spec: &SiSpec) -> Result<()> {
    super::solved::check_bounds(spec.amplitude_min, spec.amplitude_max, spec.max_duration)?;
    if let Some(n) = spec.max_impulses {
        crate::error::count("maxImpulses", n, 1, MAX_IMPULSES_PARAMETER)?;
    }
    Ok(())
}

/// `dampingRange`, checked.
fn damping_range(spec: &SiSpec) -> Result<Option<(f64, f64)>> {
    Ok(match spec.damping_range {
        Some(r) => {
            let (lo, hi) = pair("dampingRange", r, false)?;
            crate::vibration::damping_ratio("dampingRange[0]", lo)?;
            crate::vibration::damping_ratio("dampingRange[1]", hi)?;
            Some((lo, hi))
        }
        None => None,
    })
}

/// The bands, one per mode (insensitivity) or the one given (`bandHz`), each (from Hz, to Hz,
/// damping from, damping to); none when only sample frequencies are given.
fn bands(
    spec: &SiSpec,
    modes: &[Mode],
    damping_range: Option<(f64, f64)>,
) -> Result<Vec<(f64, f64, f64, f64)>> {
    let dampings_of =
        |mode: &Mode| -> (f64, f64) { damping_range.unwrap_or((mode.damping(), mode.damping())) };
    Ok(match (spec.insensitivity, spec.band_hz) {
        (Some(_), Some(_)) => {
            return Err(Error::invalid(
                "bandHz",
                "give either insensitivity or bandHz, not both",
            ))
        }
        (Some(i), None) => {
            positive("insensitivity", i)?;
            if i > MAX_INSENSITIVITY {
                return Err(Error::invalid(
                    "insensitivity",
                    format!(
                        "must be at most {MAX_INSENSITIVITY} (the band reaches 0 Hz at 2), got {i}"
                    ),
                ));
            }
            modes
                .iter()
                .map(|m| {
                    let f = m.frequency_hz();
                    let (zl, zh) = dampings_of(m);
                    (f * (1.0 - i / 2.0), f * (1.0 + i / 2.0), zl, zh)
                })
                .collect()
        }
        (None, Some(b)) => {
            if modes.len() != 1 {
                return Err(Error::invalid(
                    "bandHz",
                    "bandHz describes one band; with several modes give insensitivity instead",
                ));
            }
            let (lo, hi) = pair("bandHz", b, true)?;
            if lo <= 0.0 {
                return Err(Error::invalid(
                    "bandHz[0]",
                    format!("must be greater than 0 Hz, got {lo}"),
                ));
            }
            let (zl, zh) = dampings_of(&modes[0]);
            vec![(lo, hi, zl, zh)]
        }
        (None, None) => {
            if spec.sample_frequencies_hz.is_none() {
                return Err(Error::invalid(
                    "insensitivity",
                    "give insensitivity (band width as a fraction of the mode's frequency), \
                     bandHz or sampleFrequenciesHz",
                ));
            }
            Vec::new()
        }
    })
}

/// The limits of `sampleFrequenciesHz` (each checked, and inside the bands if there are any):
/// each sample at each mode's damping (or at the ends and middle of `dampingRange`).
fn sampled_limits(
    samples: &[f64],
    bands: &[(f64, f64, f64, f64)],
    damping_range: Option<(f64, f64)>,
    modes: &[Mode],
    tolerance: &Tolerance,
) -> Result<Vec<Limit>> {
    let mut limits = Vec::new();
    crate::error::count("sampleFrequenciesHz", samples.len(), 1, MAX_SAMPLES)?;
    for (i, &f) in samples.iter().enumerate() {
        let field = format!("sampleFrequenciesHz[{i}]");
        finite(&field, f)?;
        if !(crate::mode::MIN_FREQUENCY_HZ..=crate::mode::MAX_FREQUENCY_HZ).contains(&f) {
            return Err(Error::invalid(
                field,
                format!(
                    "must lie between {} and {} Hz, got {f}",
                    crate::mode::MIN_FREQUENCY_HZ,
                    crate::mode::MAX_FREQUENCY_HZ
                ),
            ));
        }
        if !bands.is_empty()
            && !bands
                .iter()
                .any(|b| f >= b.0 * (1.0 - 1e-12) && f <= b.1 * (1.0 + 1e-12))
        {
            return Err(Error::invalid(
                field,
                format!("{f} Hz lies outside the band the insensitivity or bandHz describes"),
            ));
        }
    }
    // Each sample at each mode's damping (or at the ends and middle of dampingRange).
    let mut dampings: Vec<f64> = match damping_range {
        Some((lo, hi)) if hi > lo => vec![lo, 0.5 * (lo + hi), hi],
        Some((lo, _)) => vec![lo],
        None => modes.iter().map(|m| m.damping()).collect(),
    };
    crate::sort::sort_by(&mut dampings, f64::total_cmp);
    dampings.dedup();
    for &f in samples {
        for &z in &dampings {
            limits.push(Limit {
                frequency_hz: f,
                damping: z,
                vtol: tolerance.at(f),
            });
        }
    }
    Ok(limits)
}

/// Designs an SI shaper for `modes`; returns it with the guarantee to verify: V ≤ Vtol at every
/// sampled point (sampled mode), or at every point of the dense check over each band.
pub(crate) fn si(spec: &SiSpec, modes: &[Mode]) -> Result<(Shaper, Guarantee, SolverReport)> {
    let problem = problem(spec, modes)?;
    let design = solve::minimum_duration(&problem)?;
    if let Some(max) = spec.max_impulses {
        if design.shaper.len() > max {
            return Err(Error::Infeasible {
                reason: format!(
                    "the shortest shaper meeting this specification ({:.6} s) needs {} impulses, \
                     more than maxImpulses = {max}: allow more impulses, narrow the band or \
                     raise vtol",
                    design.shaper.duration(),
                    design.shaper.len()
                ),
            });
        }
    }
    let guarantee = Guarantee::WithinTolerance {
        points: design.checked.clone(),
        tolerance: solve::CHECK_TOLERANCE,
    };
    let report = design.report();
    Ok((design.shaper, guarantee, report))
}

/// Designs an SI shaper for `modes` (see the module docs), checked against its guarantee.
///
/// ```
/// use input_shaping::design::specified::{specified_insensitivity, SiSpec};
/// use input_shaping::{vibration::residual_vibration, Mode};
/// // V ≤ 5 % over 0.8 … 1.2 Hz (I = 0.4 around a 1 Hz mode), the shortest such shaper.
/// let spec = SiSpec { vtol: 0.05, insensitivity: Some(0.4), ..SiSpec::default() };
/// let shaper = specified_insensitivity(&spec, &[Mode::new(1.0, 0.0)?])?;
/// for k in 0..=40 {
///     let f = 0.8 + 0.4 * k as f64 / 40.0;
///     assert!(residual_vibration(&shaper, &Mode::new(f, 0.0)?) <= 0.05 + 1e-6);
/// }
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn specified_insensitivity(spec: &SiSpec, modes: &[Mode]) -> Result<Shaper> {
    let (shaper, guarantee, _) = si(spec, modes)?;
    crate::design::verify(&shaper, modes, &guarantee)?;
    Ok(shaper)
}
