//! An input shaper: a finite sequence of impulses, sorted by time, the first at t = 0.
//!
//! Shaping a command means convolving it with this sequence (Singhose 2009 Fig. 5). Shapers
//! compose by convolution: the product of a shaper for mode 1 and one for mode 2 suppresses both
//! (Singer & Seering 1988 §2.3).

use crate::error::{finite, Error, Result};
use serde::{Deserialize, Serialize};

/// Most impulses a shaper may hold (keeps memory and every evaluation bounded).
pub const MAX_IMPULSES: usize = 4096;
/// Largest |amplitude| accepted. Shapers' amplitudes are fractions of the command (±2 for
/// bang-bang); beyond this, sums of a few thousand impulses and V itself could overflow f64.
pub const MAX_AMPLITUDE: f64 = 1e12;
/// Latest impulse time accepted, in seconds: 40 periods of the slowest mode the library
/// accepts (10⁻⁹ Hz) with room to spare; beyond it, phases and products of times overflow.
pub const MAX_TIME_S: f64 = 1e12;

/// One impulse of a shaper: amplitude `amplitude` applied at `time` seconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Impulse {
    /// Time in seconds from the first impulse.
    pub time: f64,
    /// Amplitude (dimensionless; the amplitudes of a unity-gain shaper sum to 1).
    pub amplitude: f64,
}

/// A validated impulse sequence: non-empty, finite, sorted by strictly increasing time, the
/// first impulse at t = 0.
///
/// A shaper made by [`Shaper::convolve`] also remembers its factors when they are shorter in
/// total than the product: the transform of a convolution is the product of the transforms, so
/// V(ω, ζ) of the product is the product of the factors' V, and the analyses
/// ([`crate::vibration`]) evaluate Σ nₖ impulses instead of Π nₖ. Two shapers are equal when
/// their impulses are; the factors are not part of the value.
#[derive(Debug, Clone)]
pub struct Shaper {
    impulses: Vec<Impulse>,
    /// The convolution factors' impulses (each a valid shaper's), or empty when the shaper is
    /// evaluated from its own impulses.
    factors: Vec<Vec<Impulse>>,
}

impl PartialEq for Shaper {
    fn eq(&self, other: &Self) -> bool {
        self.impulses == other.impulses
    }
}

/// The wire form of a shaper: `{ impulses: [{ time, amplitude }], duration }`. `duration` is
/// written for convenience and ignored when read.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShaperData {
    /// The impulses, sorted by time, first at 0.
    pub impulses: Vec<Impulse>,
    /// Time of the last impulse in seconds.
    #[serde(default)]
    pub duration: f64,
}

/// Whether `impulses` is the identity (one unit impulse), which a convolution leaves out.
fn is_unit(impulses: &[Impulse]) -> bool {
    matches!(impulses, [only] if only.amplitude == 1.0)
}

/// Impulses closer than this (relative to the shaper's duration) are merged into one.
const MERGE_TOLERANCE: f64 = 1e-12;

impl Shaper {
    /// Builds a shaper from impulses in any order. Impulses at the same time are merged, the
    /// sequence is shifted so the first impulse is at t = 0, and impulses of exactly zero
    /// amplitude are kept only if nothing else remains.
    ///
    /// Errors: an empty list, more than [`MAX_IMPULSES`], a non-finite time or amplitude, a
    /// negative time, a time beyond [`MAX_TIME_S`] or an |amplitude| beyond [`MAX_AMPLITUDE`]
    /// (also after merging), or amplitudes that are all zero.
    pub fn new(impulses: Vec<Impulse>) -> Result<Self> {
        if impulses.is_empty() {
            return Err(Error::invalid(
                "impulses",
                "a shaper needs at least one impulse",
            ));
        }
        if impulses.len() > MAX_IMPULSES {
            return Err(Error::TooLarge {
                field: "impulses".into(),
                value: impulses.len() as f64,
                limit: MAX_IMPULSES as f64,
            });
        }
        for (i, imp) in impulses.iter().enumerate() {
            // The field names are formatted only for an error (Klipper's fit builds ~4000 shapers).
            if !imp.time.is_finite() {
                finite(&format!("impulses[{i}].time"), imp.time)?;
            }
            if !imp.amplitude.is_finite() {
                finite(&format!("impulses[{i}].amplitude"), imp.amplitude)?;
            }
            if imp.time < 0.0 {
                return Err(Error::invalid(
                    format!("impulses[{i}].time"),
                    format!("must be ≥ 0 s, got {}", imp.time),
                ));
            }
            if imp.time > MAX_TIME_S {
                return Err(Error::TooLarge {
                    field: format!("impulses[{i}].time"),
                    value: imp.time,
                    limit: MAX_TIME_S,
                });
            }
            if imp.amplitude.abs() > MAX_AMPLITUDE {
                return Err(Error::TooLarge {
                    field: format!("impulses[{i}].amplitude"),
                    value: imp.amplitude.abs(),
                    limit: MAX_AMPLITUDE,
                });
            }
        }
        if impulses.iter().all(|imp| imp.amplitude == 0.0) {
            return Err(Error::invalid("impulses", "all amplitudes are zero"));
        }
        let mut sorted = impulses;
        crate::sort::sort_by(&mut sorted, |a, b| a.time.total_cmp(&b.time));
        let t0 = sorted[0].time;
        let span = sorted[sorted.len() - 1].time - t0;
        let tol = MERGE_TOLERANCE * span.max(f64::MIN_POSITIVE);
        let mut merged: Vec<Impulse> = Vec::with_capacity(sorted.len());
        for imp in sorted {
            let t = imp.time - t0;
            match merged.last_mut() {
                Some(last) if (t - last.time).abs() <= tol => last.amplitude += imp.amplitude,
                _ => merged.push(Impulse {
                    time: t,
                    amplitude: imp.amplitude,
                }),
            }
        }
        // Amplitudes near f64::MAX can overflow when merged (or when a convolution or
        // normalisation produced them): refuse rather than return an infinite impulse.
        if let Some(k) = merged
            .iter()
            .position(|imp| imp.amplitude.is_nan() || imp.amplitude.abs() > MAX_AMPLITUDE)
        {
            return Err(Error::invalid(
                format!("impulses[{k}].amplitude"),
                format!(
                    "combining impulses at the same time gives an amplitude beyond \
                     {MAX_AMPLITUDE:e}"
                ),
            ));
        }
        merged.retain(|imp| imp.amplitude != 0.0);
        if merged.is_empty() {
            return Err(Error::invalid("impulses", "the amplitudes cancel to zero"));
        }
        // Keep the first impulse at exactly t = 0 after dropping cancelled ones.
        let first = merged[0].time;
        for imp in &mut merged {
            imp.time -= first;
        }
        Ok(Shaper {
            impulses: merged,
            factors: Vec::new(),
        })
    }

    /// Builds a shaper from its wire form.
    pub fn from_data(data: &ShaperData) -> Result<Self> {
        Shaper::new(data.impulses.clone())
    }

    /// The wire form, with the duration filled in.
    pub fn to_data(&self) -> ShaperData {
        ShaperData {
            impulses: self.impulses.clone(),
            duration: self.duration(),
        }
    }

    /// The identity shaper: one unit impulse at t = 0 (the unshaped command).
    pub fn identity() -> Self {
        Shaper {
            impulses: vec![Impulse {
                time: 0.0,
                amplitude: 1.0,
            }],
            factors: Vec::new(),
        }
    }

    /// The impulses, sorted by time, the first at t = 0.
    pub fn impulses(&self) -> &[Impulse] {
        &self.impulses
    }

    /// Number of impulses.
    pub fn len(&self) -> usize {
        self.impulses.len()
    }

    /// Always false: a shaper has at least one impulse.
    pub fn is_empty(&self) -> bool {
        self.impulses.is_empty()
    }

    /// Time of the last impulse, in seconds: the delay the shaper adds to a move.
    pub fn duration(&self) -> f64 {
        self.impulses.last().map_or(0.0, |imp| imp.time)
    }

    /// Sum of the amplitudes (1 for a shaper that keeps the command's final value).
    pub fn amplitude_sum(&self) -> f64 {
        self.impulses.iter().map(|imp| imp.amplitude).sum()
    }

    /// Centroid delay Σ Aᵢtᵢ / Σ Aᵢ in seconds: the delay a slow ramp sees through the shaper
    /// (Kamel et al. eq. 10 without the plant's own 2ζ/ω). `None` when the amplitudes sum to 0,
    /// or when the sums overflow (amplitudes near f64::MAX).
    pub fn centroid_delay(&self) -> Option<f64> {
        let sum = self.amplitude_sum();
        if sum.abs() < 1e-15 {
            return None;
        }
        let delay = self
            .impulses
            .iter()
            .map(|imp| imp.amplitude * imp.time)
            .sum::<f64>()
            / sum;
        delay.is_finite().then_some(delay)
    }

    /// The convolution of two shapers: every pair of impulses multiplied, times added.
    /// Suppresses what either suppresses (Singer & Seering 1988 §2.3).
    pub fn convolve(&self, other: &Shaper) -> Result<Shaper> {
        let n = self.len() * other.len();
        if n > MAX_IMPULSES {
            return Err(Error::TooLarge {
                field: "impulses".into(),
                value: n as f64,
                limit: MAX_IMPULSES as f64,
            });
        }
        let mut out = Vec::with_capacity(n);
        for a in &self.impulses {
            for b in &other.impulses {
                out.push(Impulse {
                    time: a.time + b.time,
                    amplitude: a.amplitude * b.amplitude,
                });
            }
        }
        let mut shaper = Shaper::new(out)?;
        // V of the product is the product of the factors' V (the transform of a convolution is
        // the product of the transforms; merging coincident impulses and dropping cancelled
        // ones change neither). Keep the factors when evaluating them is cheaper.
        let factors: Vec<Vec<Impulse>> = self
            .factors()
            .chain(other.factors())
            .filter(|f| !is_unit(f))
            .map(<[Impulse]>::to_vec)
            .collect();
        if factors.len() > 1 && factors.iter().map(Vec::len).sum::<usize>() < shaper.len() {
            shaper.factors = factors;
        }
        Ok(shaper)
    }

    /// The impulse sequences whose residual vibrations multiply to this shaper's: its
    /// convolution factors (see [`Shaper`]), or its own impulses alone.
    pub fn factors(&self) -> impl Iterator<Item = &[Impulse]> {
        let own = self.factors.is_empty().then_some(self.impulses.as_slice());
        own.into_iter()
            .chain(self.factors.iter().map(Vec::as_slice))
    }

    /// The same shaper with all times multiplied by `factor` (> 0): a shaper for a mode at
    /// frequency f, scaled by f/f', suits frequency f' when ζ = 0.
    pub fn scaled_in_time(&self, factor: f64) -> Result<Shaper> {
        crate::error::positive("factor", factor)?;
        Shaper::new(
            self.impulses
                .iter()
                .map(|imp| Impulse {
                    time: imp.time * factor,
                    amplitude: imp.amplitude,
                })
                .collect(),
        )
    }

    /// The same shaper with amplitudes divided by their sum, so they sum to 1.
    pub fn normalized(&self) -> Result<Shaper> {
        let sum = self.amplitude_sum();
        if !sum.is_finite() || sum.abs() < 1e-15 {
            return Err(Error::invalid(
                "impulses",
                "the amplitudes sum to zero; the shaper cannot be normalised",
            ));
        }
        Shaper::new(
            self.impulses
                .iter()
                .map(|imp| Impulse {
                    time: imp.time,
                    amplitude: imp.amplitude / sum,
                })
                .collect(),
        )
    }
}
