//! Mode identification: from a recording to frequencies and damping ratios, each with an
//! uncertainty (Singhose 2009 §3.2: "a frequency-domain identification scheme to estimate the
//! vibration frequencies … The system identification can also be accomplished in the time
//! domain").
//!
//! 0. **Sweep** (raw recordings, identify/sweep.rs). When the excitation is a sweep — linear
//!    (as Klipper's resonance test drives the toolhead) or exponential (a shaker's logarithmic
//!    sine sweep) — read from the data itself (the ridge of short frames, a robust straight
//!    line f(t) or ln f(t)), the modes are found and fitted on the whole record's periodogram
//!    (rectangular window, linear trend removed) inside the swept band less √r at each end
//!    (r the rate there in Hz/s, at least 4 bins; identify/raw.rs): there the periodogram
//!    is |H|²·|A|² with |A(f)|² smooth (a power of f), while a Welch average of shorter segments is lumpy
//!    (each segment sees a few hertz of the sweep) and outside the band there is only noise.
//!    Steps 1–3 then run on that periodogram (peaks smoothed over about √r/4, the
//!    rectangular window's kernel in the fit); `spectrum` stays the detection PSD. Peaks
//!    below that band (the sweep's start, where its spectrum is not smooth) narrower than
//!    √r/4 are fitted each alone on ±3 half-power widths, without the kernel (`local_fits`:
//!    slow modes rung by the start). At the sweep's end, as at a spectrum file's cliff: a
//!    response still rising into the band's top, or a peak without a 3 dB fall before it, is
//!    fitted with a mode seeded past it (never reported) and reported as
//!    [`Identification::cut_off`] unless the fit holds the mode under the end. Otherwise:
//! 1. **Peaks.** A Welch PSD (Hann, half overlap, segments of 2^⌊log₂(n/4)⌋ samples by default)
//!    is smoothed in dB over 7 bins; its local maxima with a topographic prominence of at least
//!    `minProminenceDb` inside the band are the candidate modes, the most prominent first.
//! 2. **Half-power bandwidth** (frequency domain). On a PSD whose segments are long enough
//!    that the narrowest peak spans ≥ 12 bins (when the record allows), the peak f_p
//!    (parabolic interpolation in log) and the two frequencies f₁ < f_p < f₂ where the PSD —
//!    averaged over a tenth of the peak's width so the bins' noise does not move the crossings —
//!    falls to half the peak give ζ ≈ (f₂ − f₁)/(2f_p). The natural frequency is f_p·√(1−2ζ²) for a
//!    position signal, f_p for velocity, f_p/√(1−2ζ²) for acceleration (where each |H|² peaks).
//! 3. **Spectrum fit** (frequency domain, refines 2): all modes fitted jointly to the PSD by
//!    the expected Welch estimate of a modal response to a smooth excitation — coherent modal
//!    sum with a direct term, excitation (f/f_ref)^a with a fitted, white floor, convolved with
//!    the window's kernel, Klipper's normalisation when a file has it — in log by
//!    Levenberg–Marquardt, with modes hidden on a neighbour's flank added from the residuals by
//!    an information criterion (identify/model.rs has the details). The older per-peak fit
//!    (identify/spectrum_fit.rs: white-noise excitation, kernel only near narrow peaks) is the
//!    fallback when the joint fit fails.
//! 4. **Free decay** (time domain). If the recording rings down after a hit (a block of two
//!    periods at least 20 dB above the quiet level — the lower quartile of the blocks — less
//!    than half of it two blocks earlier; the decay ends where the blocks fall below twice the
//!    quiet level), the ring-down is
//!    fitted by least squares with y(τ) = Σᵢ e^{−σᵢτ}(aᵢ cos ω_dᵢτ + bᵢ sin ω_dᵢτ) + c₀ + c₁τ
//!    (variable projection: the linear aᵢ, bᵢ, c₀, c₁ are solved for every σ, ω_d; the drift
//!    terms absorb a slow offset). This is the least-squares form of the logarithmic decrement
//!    (δ = σ·T_d), using every sample instead of two peaks. Then ωᵢ = √(σᵢ² + ω_dᵢ²),
//!    ζᵢ = σᵢ/ωᵢ.
//!
//! Uncertainties are one standard deviation: for the fits, s²(JᵀJ)⁻¹ with s² the residual
//! variance (the spectrum fit's inflated by √ENBW because neighbouring bins are correlated);
//! for the half-power estimate, the Welch variance of the bins propagated through the crossings,
//! plus half the window's noise bandwidth and the formula's bias (≈ 2.5ζ²) added in quadrature.
//! Each mode reports the spectrum fit (the half-power estimate is only its starting point and
//! the fallback when it fails), or the free-decay fit when its relative damping uncertainty is
//! smaller.

mod decay;
mod half_power;
mod model;
mod peaks;
mod raw;
mod spectrum;
mod spectrum_fit;
mod sweep;

use super::psd::{check_signal, Psd, WindowKind};
use crate::error::{count, finite, positive, Result};
use half_power::HalfPower;
use model::{fit_modes, FittedMode, ModelInput, Seed, WindowSpec};
use serde::{Deserialize, Serialize};
use spectrum_fit::spectrum_fit;
use sweep::detect_sweep;
pub use sweep::{Sweep, SweepLaw};

/// How many times narrower or broader than its peak's half-power width a fitted mode must be
/// not to describe that peak on a sweep's periodogram ([`Slot::is_line`], [`Slot::is_hump`]).
const WIDTH_FACTOR: f64 = 10.0;

/// One mode on its way out: where its peak is and every estimate made of it.
struct Slot {
    peak_hz: f64,
    peak_psd: f64,
    prominence_db: f64,
    estimates: Vec<Estimate>,
}

impl Slot {
    /// The slot of a fitted mode on no detected peak: at its own frequency, its standing over
    /// the model without it as its prominence.
    fn of_fit(m: &FittedMode) -> Self {
        Slot {
            peak_hz: m.estimate.frequency_hz,
            peak_psd: m.peak_psd,
            prominence_db: m.standing_db,
            estimates: vec![m.estimate],
        }
    }

    /// How far a spectrum-fit estimate lies from this slot's peak, in half-power half-widths
    /// of its first estimate (ζ clamped to 0.01 … 0.3).
    fn distance(&self, f: &Estimate) -> f64 {
        let e0 = self.estimates[0];
        (f.frequency_hz - e0.frequency_hz).abs() / (e0.frequency_hz * e0.damping.clamp(0.01, 0.3))
    }

    /// Whether a spectrum-fit estimate lies on this slot's peak (within three half-power
    /// half-widths of its first estimate).
    fn fits(&self, f: &Estimate) -> bool {
        self.distance(f) < 3.0
    }

    /// Whether the spectrum fit made this peak a line: at least [`WIDTH_FACTOR`] times
    /// narrower than the peak's half-power width, and its damping not told from 0 (ζ < 2σ_ζ).
    /// The peak is then no mode: a broad bump the model can fill with nothing wider than the
    /// data resolve. Seen on a sweep's whole-record periodogram, where one record's noise
    /// stands up to ~9 dB over its neighbours: a logarithmic sweep through two low-pass
    /// modes at 36.6 and 59.4 Hz (chirps seed 8's c16), whose response past them fell under
    /// the sensor's noise, showed a bump of noise spikes at 84.2 Hz (half-power ζ 0.042,
    /// 9 dB), fitted as 83.68 Hz, ζ 0.00087 ± 0.00065 and reported as a mode. Over 432 modes
    /// of nine such batches no other fit a peak kept was more than 3.2 times narrower than it.
    fn is_line(&self, f: &Estimate) -> bool {
        f.damping * WIDTH_FACTOR <= self.estimates[0].damping
            && f.damping < 2.0 * f.damping_uncertainty
    }

    /// Whether the spectrum fit made this peak a hump at least [`WIDTH_FACTOR`] times broader
    /// than the peak: not the peak's fit (it models the response's trend around it), and the
    /// peak keeps its half-power estimate. A linear sweep (5 → 197 Hz in 5.1 s, base-excited,
    /// chirps seed 10's c19) through 63.6 Hz, ζ 0.045 and two weak broad modes: the peak at
    /// 62.5 Hz (half-power 62.28 Hz, ζ 0.059) was fitted as 61.48 Hz, ζ 0.68 and reported so.
    /// Over nine other batches no fit kept by a peak was more than 1.5 times broader than it.
    fn is_hump(&self, f: &Estimate) -> bool {
        f.damping >= WIDTH_FACTOR * self.estimates[0].damping
    }

    /// Adds a spectrum-fit estimate unless it wandered off the peak.
    fn push_fit(&mut self, f: Estimate) {
        if self.fits(&f) {
            self.estimates.push(f);
        }
    }

    fn into_mode(self) -> IdentifiedMode {
        // The spectrum fit refines the half-power estimate; the free-decay fit replaces it
        // when its relative damping uncertainty is smaller.
        let estimates = self.estimates;
        let relative = |e: &Estimate| e.damping_uncertainty / e.damping;
        let fit = estimates.iter().find(|e| e.method == Method::SpectrumFit);
        let decay = estimates.iter().find(|e| e.method == Method::FreeDecay);
        let best = match (fit, decay) {
            (Some(f), Some(d)) if relative(d) < relative(f) => *d,
            (Some(f), _) => *f,
            (None, Some(d)) => *d,
            (None, None) => estimates[0],
        };
        IdentifiedMode {
            frequency_hz: best.frequency_hz,
            damping: best.damping,
            frequency_uncertainty_hz: best.frequency_uncertainty_hz,
            damping_uncertainty: best.damping_uncertainty,
            method: best.method,
            peak_frequency_hz: self.peak_hz,
            peak_psd: self.peak_psd,
            prominence_db: self.prominence_db,
            estimates,
        }
    }
}

/// The joint fit of [`model`] seeded by the half-power estimates: each fitted mode joins its
/// seed's slot; modes found in the residuals get slots of their own. `beyond`, a mode seeded
/// past the band's top, is not reported unless the fit brings it back under the sweep's end
/// onto the top that the end shows (its frequency, the pair's second).
/// None when the fit failed; else what became of `beyond`.
fn joint_fit(
    input: &ModelInput,
    halves: &[HalfPower],
    beyond: Option<(Seed, f64)>,
    max_modes: usize,
    both_forms: bool,
    slots: &mut Vec<Slot>,
) -> Option<PastFit> {
    let near_hz = beyond.map_or(f64::NAN, |b| b.1);
    let beyond = beyond.map(|b| b.0);
    let mut seeds: Vec<Seed> = halves
        .iter()
        .enumerate()
        .map(|(i, h)| Seed {
            frequency_hz: h.estimate.frequency_hz,
            damping: h.estimate.damping,
            peak_psd: h.peak_psd,
            peak: Some(i),
        })
        .collect();
    // A mode past the band's top (a response cut off by a sweep's end), fitted so that its
    // flank is not read as modes inside the band, and never reported: the file does not hold
    // its peak.
    let past = seeds.len();
    seeds.extend(beyond.map(|s| Seed {
        peak: Some(past),
        ..s
    }));
    let fitted = if both_forms && input.kind == SignalKind::Acceleration {
        // The low-pass form: a mode term fᵢ²/Dᵢ (the model's p = 0, as for a position signal)
        // rather than ν²/Dᵢ plus the direct term, kept when it fits better (see `identify`).
        let low_pass = ModelInput {
            kind: SignalKind::Position,
            ..*input
        };
        match (
            fit_modes(input, &seeds, max_modes),
            fit_modes(&low_pass, &seeds, max_modes),
        ) {
            (Some(a), Some(b)) => Some(if b.bic < a.bic - 10.0 && b.modes.len() <= a.modes.len() {
                b
            } else {
                a
            }),
            (a, b) => a.or(b),
        }?
    } else {
        fit_modes(input, &seeds, max_modes)?
    };
    let end = input.sweep_end_hz.unwrap_or(f64::INFINITY);
    // Stands 3 dB or more over the model without it at the band's top: the end needs it.
    let mut past_fit = if beyond.is_some() && fitted.top_db.get(past).is_some_and(|&db| db >= 3.0) {
        PastFit::Needed
    } else {
        PastFit::NotNeeded
    };
    let (mut seeded, mut found) = (Vec::new(), Vec::new());
    for m in fitted.modes {
        let (f, z) = (m.estimate.frequency_hz, m.estimate.damping);
        match m.peak {
            // Fitted back into the band, its peak and high half-power point under the end, on
            // the top the end shows (within 2 bins or its half-power width: not a mode
            // elsewhere the seed wandered to), standing ≥ 3 dB over the model without it (as
            // a mode found in the residuals must) at its frequency and at the fitted bins: a
            // mode the file holds after all (a peak a few bins under the end whose fall into
            // the cliff's smear is under the 3 dB the peak search asks for). Not a line
            // between two bins that no bin shows: a resonances file with no mode in its band,
            // its PSD rising as f² into the end at 133 Hz, read 130.45 Hz, ζ 0.00001,
            // standing 8.3 dB at its frequency and 0.0 dB at every bin.
            Some(i)
                if i == past
                    && f * (1.0 + z) <= end
                    && (f - near_hz).abs() <= (2.0 * input.resolution_hz).max(2.0 * z * f)
                    && m.standing_db >= 3.0
                    && m.binned_db >= 3.0 =>
            {
                past_fit = PastFit::Held;
                slots.push(Slot::of_fit(&m))
            }
            Some(i) if i == past => {}
            Some(i) => seeded.push((i, m)),
            None => found.push(m),
        }
    }
    // On a sweep's periodogram (one record, no averaging), a detected peak the fit made an
    // unresolved line of is no mode (`Slot::is_line`): its slot goes.
    let estimates = seeded.iter().map(|(_, m)| m.estimate).collect();
    let (lines, placed) = place_seeded(&mut slots[..halves.len()], estimates, input.one_record());
    let mut k = 0;
    slots.retain(|_| {
        k += 1;
        !lines.get(k - 1).copied().unwrap_or(false)
    });
    place_found(slots, found);
    let wandered = seeded
        .into_iter()
        .zip(placed)
        .filter_map(|((i, m), placed)| (!placed).then_some((halves[i].peak_hz, m)));
    place_wandered(
        slots,
        wandered,
        input.residual_standing_db,
        input.rough_below_hz,
    );
    Some(past_fit)
}

/// Gives a mode seeded on a detected peak that the fit moved off every free peak a slot of its
/// own, when another fitted mode took the peak it left (the slot holds a spectrum-fit
/// estimate now: the model that was kept has both) and it stands as a mode found in the
/// residuals must ([`model::stands_as_new`] with `standing_db` and `rough_below_hz`) on no
/// other slot. The fit may trade a seed for a
/// mode found later: a resonances file (`sweep_random.py` seed 58's f10: 83.8 / 0.147 and
/// 114.5 / 0.048, only the 114.5 Hz peak detected) fitted the seed at 75.4 / 0.164 (the broad
/// mode), then the residual mode seeded at 115.6 Hz converged to 115.06 / 0.040 and the seed
/// to 83.60 / 0.133, the pair's BIC −237 against −62; the seed's mode, on no peak, was
/// dropped, and only 115.1 Hz was reported. Other wandered modes are dropped, as before
/// ([`place_seeded`]).
fn place_wandered(
    slots: &mut Vec<Slot>,
    wandered: impl Iterator<Item = (f64, FittedMode)>,
    standing_db: f64,
    rough_below_hz: f64,
) {
    for (left_hz, m) in wandered {
        let (f, z) = (m.estimate.frequency_hz, m.estimate.damping);
        let stands = model::stands_as_new(rough_below_hz, f, z, m.standing_db, standing_db);
        let taken = slots.iter().any(|s| {
            s.peak_hz == left_hz && s.estimates.iter().any(|e| e.method == Method::SpectrumFit)
        });
        let elsewhere = slots.iter().any(|s| s.fits(&m.estimate));
        if taken && !elsewhere && stands {
            slots.push(Slot::of_fit(&m));
        }
    }
}

/// Gives each fitted mode seeded on a detected peak the slot of the peak it lies on: the
/// nearest pairs first (in half-power half-widths of the peak's first estimate, within three,
/// as [`Slot::fits`]), one mode to a slot. The fit may swap two seeds' modes: a resonances
/// file's peaks at 62.0 (ζ 0.042) and 98.2 Hz (ζ 0.131, its half-power band 38 Hz wide)
/// fitted as 99.79 / 0.1365 from the first seed and 62.99 / 0.0269 from the second, and by
/// seed the second slot took 62.99 Hz while the first kept its half-power seed: 61.98 and
/// 62.99 Hz were reported, 99.8 Hz lost. A mode on no free peak is not placed (it wandered
/// off: `false` in the second vector returned; [`place_wandered`] decides).
/// With `sweep`, a mode that is an unresolved line on its peak ([`Slot::is_line`]) is not
/// added and the slots it fell on are returned marked (`true`), for the caller to drop; one
/// that is a hump far broader than its peak ([`Slot::is_hump`]) is not added either.
fn place_seeded(slots: &mut [Slot], seeded: Vec<Estimate>, sweep: bool) -> (Vec<bool>, Vec<bool>) {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for (k, e) in seeded.iter().enumerate() {
        for (j, slot) in slots.iter().enumerate() {
            if slot.fits(e) {
                pairs.push((slot.distance(e), k, j));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut mode_done, mut slot_done) = (vec![false; seeded.len()], vec![false; slots.len()]);
    let mut lines = vec![false; slots.len()];
    for (_, k, j) in pairs {
        if !mode_done[k] && !slot_done[j] {
            mode_done[k] = true;
            slot_done[j] = true;
            if sweep && slots[j].is_line(&seeded[k]) {
                lines[j] = true;
            } else if !(sweep && slots[j].is_hump(&seeded[k])) {
                slots[j].push_fit(seeded[k]);
            }
        }
    }
    (lines, mode_done)
}

/// Gives each mode found in the residuals (or split off a broad one) its slot. One that lands
/// on a detected peak whose own fitted mode went elsewhere (the slot holds no spectrum-fit
/// estimate) is that peak's fit, not a second mode at its frequency: a fast log sweep
/// reported 111.18 Hz from the peak's half-power seed beside the fit's 111.19 Hz. The others
/// are modes of their own.
fn place_found(slots: &mut Vec<Slot>, found: Vec<FittedMode>) {
    for m in found {
        match slots.iter_mut().find(|s| {
            !s.estimates.iter().any(|e| e.method == Method::SpectrumFit) && s.fits(&m.estimate)
        }) {
            Some(slot) => slot.push_fit(m.estimate),
            None => slots.push(Slot::of_fit(&m)),
        }
    }
}

/// Whether a response rising into a sweep's end (its top at `top_hz`) is reported as cut off,
/// given what the joint fit made of the mode seeded past the end: not when the fit held it
/// under the end; yes when the end needed it; otherwise yes unless a seeded peak lies within
/// `near_hz` of the top (a mode just under the end explains it).
fn cut_off(past: Option<PastFit>, halves: &[HalfPower], top_hz: f64, near_hz: f64) -> bool {
    match past {
        Some(PastFit::Held) => false,
        Some(PastFit::Needed) => true,
        _ => !halves.iter().any(|h| (h.peak_hz - top_hz).abs() <= near_hz),
    }
}

/// The user's note for [`Identification::cut_off`], when there is one. With no mode found
/// under the end (`none_found`), the rise may be the excitation's alone (a stiff machine's PSD
/// rises as the drive's f² into the end: the test set's `rigid133`), and the note says so.
fn note_cut_off(result: &mut Identification, none_found: bool) {
    if let Some(c) = result.cut_off {
        let what = if result.sweep.is_some() {
            "recording"
        } else {
            "file"
        };
        let (f, db) = (c.frequency_hz, c.prominence_db);
        result.notes.push(if none_found {
            format!(
                "The response still rises where the sweep ends ({f:.1} Hz, {db:.0} dB over its \
                 left flank) and no mode was found under it: a mode peaks near or past the end, \
                 or the machine has none in this {what}'s band and the rise is the excitation's \
                 own. Re-run the test with a higher maximum frequency to tell which."
            )
        } else {
            format!(
                "The response still rises where the sweep ends ({f:.1} Hz, {db:.0} dB over its \
                 left flank): a mode peaks near or past the end, its frequency and damping \
                 cannot be read from this {what}. Re-run the test with a higher maximum \
                 frequency."
            )
        });
    }
}

/// What became of the mode seeded past the band's top ([`joint_fit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum PastFit {
    /// Fitted back under the sweep's end: a mode of the band.
    Held,
    /// Past the band, standing ≥ 3 dB at its top: a response cut off by the end.
    Needed,
    /// Not needed (or none seeded): the band's own modes explain its top.
    NotNeeded,
}

/// The peaks of a sweep's start (identify/raw.rs, `start_peaks`), each fitted alone on its
/// own band by the joint model with one mode, without the window's kernel: the periodogram of
/// a mode the sweep's start rang, which has died out within the record, is the spectrum of
/// the whole response — no leakage to model (the kernel would read the peak as narrower
/// than it is). A mode joins the slots when the fit stays on its peak, stands ≥ 3 dB over
/// the model without it (as a mode found in the residuals must) and is resolved: its
/// half-power width at least 1.5 bins (a steady line — a slow sweep's harmonic — is one bin
/// wide, 0.89 for the rectangular window, and cannot be told from a mode narrower than that).
fn local_fits(psd: &Psd, locals: &[raw::Local], kind: SignalKind, slots: &mut Vec<Slot>) {
    let df = psd.resolution_hz;
    for l in locals {
        let input = ModelInput {
            frequency_hz: &psd.frequency_hz,
            psd: &psd.psd,
            resolution_hz: df,
            even: true,
            window: None,
            klipper_normalized: false,
            kind,
            enbw_bins: psd.enbw_bins,
            band: l.band,
            sweep_end_hz: None,
            stationary: false,
            rough_below_hz: 0.0,
            residual_standing_db: model::SPECTRUM_STANDING_DB,
        };
        let seed = Seed {
            frequency_hz: l.half.estimate.frequency_hz,
            damping: l.half.estimate.damping,
            peak_psd: l.half.peak_psd,
            peak: Some(0),
        };
        let Some(fitted) = fit_modes(&input, &[seed], 1) else {
            continue;
        };
        let Some(m) = fitted.modes.into_iter().find(|m| m.peak == Some(0)) else {
            continue;
        };
        let width = 2.0 * m.estimate.damping * m.estimate.frequency_hz;
        if width < 1.5 * df || m.standing_db < 3.0 {
            continue;
        }
        let mut slot = Slot {
            peak_hz: l.half.peak_hz,
            peak_psd: l.half.peak_psd,
            prominence_db: l.peak.prominence_db,
            estimates: vec![l.half.estimate],
        };
        slot.push_fit(m.estimate);
        if slot.estimates.len() == 2 {
            slots.push(slot);
        }
    }
}

/// Most modes [`identify`] returns.
pub const MAX_MODES: usize = 8;

/// What the signal measures (sets the exponent p of the spectrum model).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum SignalKind {
    /// Acceleration (accelerometers, Klipper's files; default).
    #[default]
    Acceleration,
    /// Velocity.
    Velocity,
    /// Position or deflection.
    Position,
}

impl SignalKind {
    fn power(self) -> i32 {
        match self {
            SignalKind::Acceleration => 2,
            SignalKind::Velocity => 1,
            SignalKind::Position => 0,
        }
    }
}

/// Options of [`identify`] (JS: `{ sampleRateHz, signal, maxModes, minFrequencyHz,
/// maxFrequencyHz, minProminenceDb, segmentLength, freeDecay }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct IdentifyOptions {
    /// Sampling rate, Hz (required).
    pub sample_rate_hz: f64,
    /// What the signal measures (default acceleration).
    pub signal: SignalKind,
    /// Most modes to return, 1 … [`MAX_MODES`] (default 3).
    pub max_modes: usize,
    /// Lowest frequency searched (default 4 bins of the detection PSD), Hz.
    pub min_frequency_hz: Option<f64>,
    /// Highest frequency searched (default 0.45 f_s), Hz.
    pub max_frequency_hz: Option<f64>,
    /// Least prominence of a peak over the smoothed spectrum around it, dB (default 6).
    pub min_prominence_db: f64,
    /// Segment length of the detection PSD (default 2^⌊log₂(n/8)⌋, 64 … 65536).
    pub segment_length: Option<usize>,
    /// Look for a free decay and fit it (default true).
    pub free_decay: bool,
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        IdentifyOptions {
            sample_rate_hz: f64::NAN,
            signal: SignalKind::Acceleration,
            max_modes: 3,
            min_frequency_hz: None,
            max_frequency_hz: None,
            min_prominence_db: 6.0,
            segment_length: None,
            free_decay: true,
        }
    }
}

impl IdentifyOptions {
    /// Defaults at sampling rate `sample_rate_hz`.
    pub fn new(sample_rate_hz: f64) -> Self {
        IdentifyOptions {
            sample_rate_hz,
            ..IdentifyOptions::default()
        }
    }
}

/// How an estimate was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "camelCase")]
pub enum Method {
    /// Half-power bandwidth of the PSD peak.
    HalfPower,
    /// Least-squares fit of the modal power spectrum.
    SpectrumFit,
    /// Least-squares fit of damped sinusoids to the free decay.
    FreeDecay,
}

/// One estimate of a mode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Estimate {
    /// The method.
    pub method: Method,
    /// Undamped natural frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping: f64,
    /// One standard deviation of `frequency_hz`, Hz.
    pub frequency_uncertainty_hz: f64,
    /// One standard deviation of `damping`.
    pub damping_uncertainty: f64,
}

/// An identified mode: the best estimate and all of them.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct IdentifiedMode {
    /// Undamped natural frequency (best estimate), Hz.
    pub frequency_hz: f64,
    /// Damping ratio (best estimate).
    pub damping: f64,
    /// One standard deviation of the frequency, Hz.
    pub frequency_uncertainty_hz: f64,
    /// One standard deviation of the damping ratio.
    pub damping_uncertainty: f64,
    /// Which estimate is the best one.
    pub method: Method,
    /// Frequency of the PSD peak, Hz.
    pub peak_frequency_hz: f64,
    /// PSD at the peak.
    pub peak_psd: f64,
    /// Prominence of the peak, dB.
    pub prominence_db: f64,
    /// Every estimate obtained, in the order half-power, spectrum fit, free decay.
    pub estimates: Vec<Estimate>,
}

/// Where the free decay was found.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FreeDecay {
    /// Start of the fitted ring-down, s from the first sample.
    pub start_s: f64,
    /// End of it, s from the first sample.
    pub end_s: f64,
    /// RMS of the strongest block over the quiet level (the lower quartile of the blocks), dB.
    pub level_db: f64,
}

/// What [`identify`] found.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Identification {
    /// The modes, by increasing frequency.
    pub modes: Vec<IdentifiedMode>,
    /// The PSD the estimates were made on.
    pub spectrum: Psd,
    /// Segment length of the detection PSD.
    pub detection_segment_length: usize,
    /// The band searched, Hz.
    pub band_hz: [f64; 2],
    /// The free decay, if one was found and fitted.
    pub free_decay: Option<FreeDecay>,
    /// The sweep, when the recording is one and its modes were fitted on its whole-record
    /// periodogram inside the swept band (`spectrum` is then the detection PSD).
    pub sweep: Option<Sweep>,
    /// A spectrum file's sweep end, when its PSD shows one (the last bin fitted before the
    /// cliff), Hz; `None` otherwise and for recordings.
    pub sweep_end_hz: Option<f64>,
    /// A response still rising where the sweep ends (a spectrum file's cliff, or a raw
    /// recording's detected sweep): a mode peaking near or past [`CutOff::frequency_hz`],
    /// whose peak the data do not hold. Not one of `modes` (its
    /// frequency is only a lower bound, its damping unknown: nothing to design a shaper for),
    /// but reported so that such a file does not come out as "no mode". `None` otherwise.
    pub cut_off: Option<CutOff>,
    /// What the identification could not do, in words for the user (a response cut off by
    /// the sweep's end; a raw recording's sweep whose band shows no peak). Empty when none.
    pub notes: Vec<String>,
}

/// A response cut off by the end of a sweep ([`Identification::cut_off`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct CutOff {
    /// Where the sweep ends, Hz: for a spectrum file the last bin fitted before the sweep's
    /// cliff (the mode peaks near it, within the window's smear of the cliff, ±2 bins, or past
    /// it); for a raw recording the end of its detected sweep ([`Sweep::band_hz`]).
    pub frequency_hz: f64,
    /// How far the response rises to it over the lowest point of its left flank (down to the
    /// nearest higher bin or the band's start), dB.
    pub prominence_db: f64,
}

/// Identifies the modes in `signal` (see the module docs).
///
/// Errors: fewer than 64 samples, a non-finite sample (`signal[i]`), a bad `sampleRateHz`,
/// `maxModes` outside 1 … [`MAX_MODES`], a band outside (0, f_s/2) or empty, a
/// `segmentLength` < 64 or longer than the signal. Finding no peak is not an error: `modes` is
/// empty.
pub fn identify(signal: &[f64], options: &IdentifyOptions) -> Result<Identification> {
    check_signal(signal, 64)?;
    let fs = positive("sampleRateHz", options.sample_rate_hz)?;
    count("maxModes", options.max_modes, 1, MAX_MODES)?;
    finite("minProminenceDb", options.min_prominence_db)?;
    let (psd0, n0) = raw::detection_psd(signal, fs, options)?;
    let band = raw::search_band(options, fs, psd0.resolution_hz)?;
    let mut result = Identification {
        modes: Vec::new(),
        spectrum: psd0.clone(),
        detection_segment_length: n0,
        band_hz: band,
        free_decay: None,
        sweep: None,
        sweep_end_hz: None,
        cut_off: None,
        notes: Vec::new(),
    };
    // A sweep (unless the segments are given): its whole-record periodogram inside its band;
    // otherwise the Welch path.
    let sweep = options
        .segment_length
        .is_none()
        .then(|| detect_sweep(signal, fs))
        .flatten();
    let mut stage = match sweep {
        Some(s) => raw::sweep_stage(signal, fs, s, band, options)?,
        None => None,
    };
    if let Some(s) = sweep {
        // A sweep's band with no peak: no mode to read there, and the Welch path, not meant
        // for sweeps, would read its lumps as modes.
        result.sweep = sweep;
        if s.partial {
            result.notes.push(format!(
                "The sweep stands over the sensor's noise only over {:.1}–{:.1} Hz of the \
                 record: modes outside that band cannot be read from it (a stronger drive or \
                 a quieter sensor would show them).",
                s.band_hz[0], s.band_hz[1]
            ));
        }
        if stage.is_none() {
            let law = match s.law {
                SweepLaw::Linear => "",
                SweepLaw::Exponential => "an exponential sweep, ",
            };
            result.notes.push(format!(
                "A sweep was found ({:.1}–{:.1} Hz, {law}at {:.2} Hz/s) but no mode stands out \
                 in the band fitted inside it: the response there is flat, or the band is too \
                 narrow for this sweep rate.",
                s.band_hz[0], s.band_hz[1], s.rate_hz_per_s
            ));
            return Ok(result);
        }
    } else {
        stage = raw::welch_stage(signal, psd0, n0, band, options)?;
    }
    let Some(stage) = stage else {
        return Ok(result);
    };
    let raw::Stage {
        psd,
        found,
        band,
        local,
        rising,
    } = stage;
    let halves: Vec<HalfPower> = found.iter().map(|(_, h)| *h).collect();
    let mut slots: Vec<Slot> = found
        .iter()
        .map(|(p, h)| Slot {
            peak_hz: h.peak_hz,
            peak_psd: h.peak_psd,
            prominence_db: p.prominence_db,
            estimates: vec![h.estimate],
        })
        .collect();
    let input = ModelInput {
        frequency_hz: &psd.frequency_hz,
        psd: &psd.psd,
        resolution_hz: psd.resolution_hz,
        even: true,
        window: Some(WindowSpec {
            kind: if result.sweep.is_some() {
                WindowKind::Rectangular
            } else {
                WindowKind::Hann
            },
            length: psd.segment_length,
            symmetric: false,
            beta: 6.0,
        }),
        klipper_normalized: false,
        kind: options.signal,
        enbw_bins: psd.enbw_bins,
        band,
        sweep_end_hz: result.sweep.map(|s| s.band_hz[1]),
        stationary: result.sweep.is_none(),
        // Klipper's pulse train steps its frequency by r/(2f) every cycle: near a fast
        // sweep's start the steps are wide and its spectrum lumpy up to about 4√r (5 → 200 Hz
        // in 2 s: ±3–7 dB over a few hertz up to ~30 Hz); a sine chirp's ripple stays within
        // √r of its start, inside the band's margin.
        rough_below_hz: result
            .sweep
            .map_or(0.0, |s| 4.0 * s.rate_at(s.band_hz[0]).sqrt()),
        residual_standing_db: if result.sweep.is_some() {
            model::RESIDUAL_STANDING_DB
        } else {
            model::SPECTRUM_STANDING_DB
        },
    };
    // A response rising into a sweep's end: as for a spectrum file's cliff
    // (`identify_spectrum`), a mode seeded past the band, reported as cut off unless the fit
    // holds it under the end.
    let beyond = rising.map(|r| {
        let seed = Seed {
            frequency_hz: r.seed_hz,
            damping: 0.05,
            peak_psd: r.level,
            peak: None,
        };
        (seed, psd.frequency_hz[r.top])
    });
    // A sweep's modes are fitted in both mode forms (`joint_fit`): the accelerometer on a
    // base-driven structure reads 1 + ν²/D (the transmissibility), a mass pulled through a
    // spring and damped to the frame f²/D, and the wrong one biases broad modes (a flat
    // logarithmic sweep through low-pass modes: 113.1 Hz, ζ 0.038 read 109.6, ζ 0.053).
    let both_forms = result.sweep.is_some();
    let joint = joint_fit(
        &input,
        &halves,
        beyond,
        options.max_modes,
        both_forms,
        &mut slots,
    );
    if let (Some(r), Some(s)) = (rising, result.sweep) {
        // Within the stretch the top was taken from (`raw::rising_into_top`).
        let near_hz = s.rate_at(s.band_hz[1]).sqrt().max(2.0 * psd.resolution_hz);
        let top_hz = psd.frequency_hz[r.top];
        result.cut_off = cut_off(joint, &halves, top_hz, near_hz).then_some(CutOff {
            frequency_hz: s.band_hz[1],
            prominence_db: r.prominence_db,
        });
        note_cut_off(&mut result, slots.is_empty());
    }
    if joint.is_none() && !halves.is_empty() {
        let bin = |f: f64| ((f / psd.resolution_hz).round() as usize).min(psd.psd.len() - 1);
        let (lo, hi) = (bin(band[0]).max(1), bin(band[1]));
        if let Some(fits) = spectrum_fit(&psd, &halves, lo, hi, options.signal) {
            for (slot, f) in slots.iter_mut().zip(fits) {
                slot.push_fit(f);
            }
        }
    }
    local_fits(&psd, &local, options.signal, &mut slots);
    if slots.len() > options.max_modes {
        crate::sort::sort_by(&mut slots, |a, b| {
            b.prominence_db.total_cmp(&a.prominence_db)
        });
        slots.truncate(options.max_modes);
    }
    if options.free_decay && !slots.is_empty() {
        result.free_decay = raw::free_decay_stage(signal, fs, &mut slots);
    }
    result.modes = slots.into_iter().map(Slot::into_mode).collect();
    crate::sort::sort_by(&mut result.modes, |a, b| {
        a.frequency_hz.total_cmp(&b.frequency_hz)
    });
    if result.sweep.is_none() {
        result.spectrum = psd;
    }
    Ok(result)
}

/// Identifies the modes in a spectrum alone (a Klipper spectrum file, or a raw file's Klipper
/// spectrum): the peaks of `spectrum.psd` (3-bin smoothing: Klipper's bins are coarse) seed the
/// joint fit of the module docs' step 3 (identify/model.rs), which models Klipper's Welch
/// window (symmetric Kaiser β = 6) and,
/// when `spectrum.normalization` says so, its normalisation (fitted above 10 Hz only, where the
/// released and the current Klipper agree: psd/(f + 0.1)). `options.sampleRateHz` is not used;
/// the band defaults to [5 Hz or the second bin, the last bin].
///
/// Errors: fewer than 8 bins, an uneven or non-increasing frequency column, a negative or
/// non-finite PSD (`spectrum.psd[i]`), and the option errors of [`identify`].
pub fn identify_spectrum(
    spectrum: &super::spectrum_file::SpectrumFile,
    options: &IdentifyOptions,
) -> Result<Identification> {
    count("maxModes", options.max_modes, 1, MAX_MODES)?;
    finite("minProminenceDb", options.min_prominence_db)?;
    let grid = spectrum::grid(spectrum)?;
    let [f_lo, f_hi] = spectrum::band(&grid, options)?;
    let psd = &grid.psd;
    let (df, n) = (psd.resolution_hz, psd.psd.len());
    let lo = ((f_lo / df).ceil() as usize).clamp(1, n - 1);
    let hi = ((f_hi / df).floor() as usize).min(n - 1);
    let mut result = Identification {
        modes: Vec::new(),
        spectrum: psd.clone(),
        detection_segment_length: psd.segment_length,
        band_hz: [f_lo, f_hi],
        free_decay: None,
        sweep: None,
        sweep_end_hz: None,
        cut_off: None,
        notes: Vec::new(),
    };
    if hi < lo + 4 {
        return Ok(result);
    }
    // The sweep's end (if the file shows one): `e` the bin before its steepest drop, the end
    // itself where the smeared step is at half its level (`spectrum::end_hz`). No peak
    // searched and no bin fitted from `e` on; the model's excitation stops at the end.
    let end = spectrum::sweep_end(&grid, lo, hi).filter(|&e| e >= lo + 5);
    let (cut, f_hi) = match end {
        Some(e) => (Some(e - 1), psd.frequency_hz[e - 1]),
        None => (None, f_hi),
    };
    let (halves, mut slots, shoulder) = spectrum::seeds(&grid, lo, hi, cut, options);
    let input = ModelInput {
        frequency_hz: &psd.frequency_hz,
        psd: &psd.psd,
        resolution_hz: df,
        even: true,
        window: Some(grid.window),
        klipper_normalized: grid.normalized,
        kind: options.signal,
        enbw_bins: psd.enbw_bins,
        band: [f_lo, f_hi],
        sweep_end_hz: end.map(|e| spectrum::end_hz(&grid, e)),
        stationary: false,
        rough_below_hz: 0.0,
        residual_standing_db: model::SPECTRUM_STANDING_DB,
    };
    // A response still rising into the sweep's end: fitted with a mode seeded past the band
    // (its flank would otherwise be read as modes under the cliff), and reported as cut off
    // unless the fit brings that mode back under the end (a peak a few bins under it).
    result.sweep_end_hz = cut.map(|_| f_hi);
    let candidate = cut.and_then(|c| {
        spectrum::rising_to_end(&grid, lo, c, options.min_prominence_db).map(|(p, top)| (c, p, top))
    });
    // (Without a candidate, a peak under the end whose fall into the cliff is under 3 dB gets
    // the same trial from its own bin: a mode when the fit holds it under the end.)
    let unnormalized = |k: usize| {
        let f = psd.frequency_hz[k];
        psd.psd[k] * if grid.normalized { f + 0.1 } else { 1.0 }
    };
    let beyond = match (candidate, shoulder) {
        (Some((c, _, top)), _) => Some((1.05 * f_hi, unnormalized(c), top)),
        (None, Some(k)) => Some((psd.frequency_hz[k], unnormalized(k), k)),
        _ => None,
    }
    .map(|(frequency_hz, peak_psd, top)| {
        let seed = Seed {
            frequency_hz,
            damping: 0.05,
            peak_psd,
            peak: None,
        };
        (seed, psd.frequency_hz[top])
    });
    let past = joint_fit(
        &input,
        &halves,
        beyond,
        options.max_modes,
        false,
        &mut slots,
    );
    result.cut_off = candidate
        .filter(|&(_, _, top)| cut_off(past, &halves, psd.frequency_hz[top], 2.0 * df))
        .map(|(_, prominence_db, _)| CutOff {
            frequency_hz: f_hi,
            prominence_db,
        });
    note_cut_off(&mut result, slots.is_empty());
    result.modes = slots.into_iter().map(Slot::into_mode).collect();
    crate::sort::sort_by(&mut result.modes, |a, b| {
        a.frequency_hz.total_cmp(&b.frequency_hz)
    });
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(method: Method, frequency_hz: f64, damping: f64) -> Estimate {
        Estimate {
            method,
            frequency_hz,
            damping,
            frequency_uncertainty_hz: 0.01 * frequency_hz,
            damping_uncertainty: 0.1 * damping,
        }
    }

    fn slot(estimates: Vec<Estimate>) -> Slot {
        Slot {
            peak_hz: estimates[0].frequency_hz,
            peak_psd: 1.0,
            prominence_db: 20.0,
            estimates,
        }
    }

    fn found(frequency_hz: f64, damping: f64) -> FittedMode {
        FittedMode {
            estimate: estimate(Method::SpectrumFit, frequency_hz, damping),
            peak: None,
            peak_psd: 0.5,
            standing_db: 8.0,
            binned_db: 8.0,
        }
    }

    /// A generated resonances file (two modes 63.0 / 0.027 and 99.8 / 0.136 with a third at
    /// 139 Hz): the joint fit returned the seeds' modes swapped. Each goes to the peak it
    /// lies on; by seed index the broad peak's slot took 62.99 Hz and the sharp peak kept
    /// only its half-power seed, and 99.8 Hz was lost.
    #[test]
    fn fitted_modes_swapped_by_the_fit_go_to_the_peaks_they_lie_on() {
        let mut slots = vec![
            slot(vec![estimate(Method::HalfPower, 61.98, 0.0418)]),
            slot(vec![estimate(Method::HalfPower, 98.18, 0.1312)]),
        ];
        // In the seeds' order: the first seed's fit went to the broad mode.
        let seeded = vec![
            estimate(Method::SpectrumFit, 99.79, 0.1365),
            estimate(Method::SpectrumFit, 62.99, 0.0269),
        ];
        place_seeded(&mut slots, seeded, true);
        let modes: Vec<IdentifiedMode> = slots.into_iter().map(Slot::into_mode).collect();
        assert_eq!(
            modes
                .iter()
                .map(|m| (m.frequency_hz, m.damping, m.method))
                .collect::<Vec<_>>(),
            [
                (62.99, 0.0269, Method::SpectrumFit),
                (99.79, 0.1365, Method::SpectrumFit)
            ]
        );
    }

    /// One mode to a slot, nearest first; a mode on no peak (it wandered off) is dropped and
    /// its peak keeps its half-power estimate.
    #[test]
    fn one_fitted_mode_to_a_peak_and_none_off_the_peaks() {
        let mut slots = vec![
            slot(vec![estimate(Method::HalfPower, 50.0, 0.05)]),
            slot(vec![estimate(Method::HalfPower, 120.0, 0.03)]),
        ];
        let seeded = vec![
            estimate(Method::SpectrumFit, 51.0, 0.05),
            estimate(Method::SpectrumFit, 50.2, 0.05),
            estimate(Method::SpectrumFit, 90.0, 0.05),
        ];
        place_seeded(&mut slots, seeded, true);
        assert_eq!(slots[0].estimates.len(), 2);
        assert_eq!(slots[0].estimates[1].frequency_hz, 50.2);
        assert_eq!(slots[1].estimates.len(), 1);
    }

    /// On a sweep, a fit that made its peak an unresolved line (≥ 10 times narrower than the
    /// peak's half-power width, ζ < 2σ_ζ) marks the peak for dropping (chirps seed 8's c16:
    /// 84.17 Hz, ζ 0.0423 fitted as 83.68 Hz, ζ 0.00087 ± 0.00065); a narrow fit whose
    /// damping is determined, or an undetermined one less than ten times narrower, is the
    /// peak's mode; on a spectrum, either is.
    #[test]
    fn a_peak_fitted_as_an_unresolved_line_is_dropped_on_a_sweep() {
        let line = |damping: f64, sigma: f64| Estimate {
            damping_uncertainty: sigma,
            ..estimate(Method::SpectrumFit, 83.68, damping)
        };
        let peaks = || {
            vec![
                slot(vec![estimate(Method::HalfPower, 36.61, 0.0148)]),
                slot(vec![estimate(Method::HalfPower, 84.17, 0.0423)]),
            ]
        };
        let fits = |l: Estimate| vec![estimate(Method::SpectrumFit, 36.59, 0.0128), l];
        let mut slots = peaks();
        assert_eq!(
            place_seeded(&mut slots, fits(line(0.00087, 0.00065)), true).0,
            [false, true]
        );
        assert_eq!(slots[1].estimates.len(), 1);
        // Its damping told from 0 (2σ under ζ), or 9.4 times narrower only: the peak's mode.
        for l in [line(0.00087, 0.0004), line(0.0045, 0.004)] {
            let mut slots = peaks();
            assert_eq!(place_seeded(&mut slots, fits(l), true).0, [false, false]);
            assert_eq!(slots[1].estimates.len(), 2);
        }
        // Not on a spectrum (Welch averages, a spectrum file).
        let mut slots = peaks();
        assert_eq!(
            place_seeded(&mut slots, fits(line(0.00087, 0.00065)), false).0,
            [false, false]
        );
    }

    /// On a sweep, a fit ten or more times broader than its peak is not the peak's: the peak
    /// keeps its half-power estimate (chirps seed 10's c19: 62.28 Hz, ζ 0.0594 fitted as
    /// 61.48 Hz, ζ 0.6773); a fit 1.5 times broader is the peak's; on a spectrum, either is.
    #[test]
    fn a_hump_far_broader_than_its_peak_is_not_placed_on_a_sweep() {
        let peak = || vec![slot(vec![estimate(Method::HalfPower, 62.28, 0.0594)])];
        let mut slots = peak();
        let hump = vec![estimate(Method::SpectrumFit, 61.48, 0.6773)];
        assert_eq!(place_seeded(&mut slots, hump.clone(), true).0, [false]);
        assert_eq!(slots[0].estimates.len(), 1);
        assert_eq!(slots.remove(0).into_mode().method, Method::HalfPower);
        let mut slots = peak();
        place_seeded(
            &mut slots,
            vec![estimate(Method::SpectrumFit, 62.3, 0.09)],
            true,
        );
        assert_eq!(slots[0].estimates.len(), 2);
        let mut slots = peak();
        place_seeded(&mut slots, hump, false);
        assert_eq!(slots[0].estimates.len(), 2);
    }

    /// The defect of 344aa08 (a fast log sweep of `sweep_chirps.py`, chirps seed 1's c08):
    /// the detected 111.18 Hz peak kept only its half-power seed when its own fitted mode
    /// went elsewhere, the fit's 111.19 Hz came back from the residuals, and both were
    /// reported. Joining a slot without a fit of its own makes one mode of them.
    #[test]
    fn a_residual_mode_on_a_peak_without_its_own_fit_joins_that_peak() {
        let mut slots = vec![
            slot(vec![estimate(Method::HalfPower, 52.0, 0.05)]),
            slot(vec![estimate(Method::HalfPower, 111.18, 0.04)]),
        ];
        // The first peak's fit stayed home; the second's did not.
        slots[0].push_fit(estimate(Method::SpectrumFit, 52.1, 0.049));
        place_found(&mut slots, vec![found(111.19, 0.035)]);
        assert_eq!(slots.len(), 2);
        let modes: Vec<IdentifiedMode> = slots.into_iter().map(Slot::into_mode).collect();
        assert_eq!(modes[1].method, Method::SpectrumFit);
        assert_eq!(modes[1].frequency_hz, 111.19);
        assert_eq!(modes[1].damping, 0.035);
        assert_eq!(modes[1].peak_frequency_hz, 111.18);
        assert_eq!(modes[1].estimates.len(), 2);
    }

    /// A mode near a peak that has its own fit (one half of a split pair), or away from every
    /// peak, is a mode of its own, reported with what the fit says of it.
    #[test]
    fn other_residual_modes_are_modes_of_their_own() {
        let mut slots = vec![slot(vec![
            estimate(Method::HalfPower, 56.0, 0.12),
            estimate(Method::SpectrumFit, 55.9, 0.12),
        ])];
        place_found(&mut slots, vec![found(60.0, 0.1), found(140.0, 0.02)]);
        assert_eq!(slots.len(), 3);
        let modes: Vec<IdentifiedMode> = slots.into_iter().map(Slot::into_mode).collect();
        assert_eq!(modes[0].frequency_hz, 55.9);
        assert_eq!(modes[0].estimates.len(), 2);
        for (m, f) in modes[1..].iter().zip([60.0, 140.0]) {
            assert_eq!(m.frequency_hz, f);
            assert_eq!(m.peak_frequency_hz, f);
            assert_eq!(m.prominence_db, 8.0);
            assert_eq!(m.estimates.len(), 1);
        }
    }

    /// A seeded mode the fit moved off every peak (seed 58's f10: seeded at 114.5 Hz, ended at
    /// 83.6 Hz, ζ 0.133) is a mode of its own once another fitted mode took the peak it left,
    /// when it stands as a residual mode must (3 dB on a spectrum, 8 dB where a fast sweep's
    /// drive is rough) with ζ < 0.3 on no slot of its own; otherwise it is dropped, as before.
    #[test]
    fn a_seed_traded_for_a_later_mode_keeps_its_fit() {
        let peak = || vec![slot(vec![estimate(Method::HalfPower, 114.5, 0.058)])];
        let wandered = |f: f64, z: f64, db: f64| FittedMode {
            standing_db: db,
            ..found(f, z)
        };
        // The residual mode took the peak: the seed's mode is kept.
        let mut slots = peak();
        place_found(&mut slots, vec![found(115.06, 0.040)]);
        place_wandered(
            &mut slots,
            [(114.5, wandered(83.6, 0.133, 9.0))].into_iter(),
            3.0,
            0.0,
        );
        let modes: Vec<IdentifiedMode> = slots.into_iter().map(Slot::into_mode).collect();
        assert_eq!(modes.len(), 2);
        assert_eq!(modes[0].frequency_hz, 115.06);
        assert_eq!(modes[1].frequency_hz, 83.6);
        assert_eq!(modes[1].damping, 0.133);
        assert_eq!(modes[1].prominence_db, 9.0);
        // The peak it left has no fit: dropped.
        let mut slots = peak();
        place_wandered(
            &mut slots,
            [(114.5, wandered(83.6, 0.133, 9.0))].into_iter(),
            3.0,
            0.0,
        );
        assert_eq!(slots.len(), 1);
        // Standing under the threshold, as broad as ζ 0.3, or on another slot: dropped.
        for (f, z, db) in [(83.6, 0.133, 2.9), (83.6, 0.3, 9.0), (115.5, 0.05, 9.0)] {
            let mut slots = peak();
            place_found(&mut slots, vec![found(115.06, 0.040)]);
            place_wandered(
                &mut slots,
                [(114.5, wandered(f, z, db))].into_iter(),
                3.0,
                0.0,
            );
            assert_eq!(slots.len(), 1, "{f} {z} {db}");
        }
        // Where a fast sweep's drive is rough, it must stand 8 dB.
        let mut slots = peak();
        place_found(&mut slots, vec![found(115.06, 0.040)]);
        let rough = [(114.5, wandered(83.6, 0.133, 7.9))].into_iter();
        place_wandered(&mut slots, rough, 3.0, 90.0);
        assert_eq!(slots.len(), 1);
    }
}
