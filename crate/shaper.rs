//! An input shaper: a finite sequence of impulses, sorted by time, the first at t = 0.
//!
//! Shaping a command means convolving it with this sequence (Singhose 2009 Fig. 5). Shapers
//! compose by convolution: the product of a shaper for mode 1 and one for mode 2 suppresses both
//! (Singer & Seering 1988 §2.3).

use crate::error::{finite, Error, Result};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// Most impulses a shaper may hold (keeps memory and every evaluation bounded).
pub const MAX_IMPULSES: usize = 4096;
/// Most impulses a convolution may stand for (the product of its factors' counts). Beyond
/// [`MAX_IMPULSES`] a convolution stays factored: it is analysed and simulated from its factors
/// (Σ nₖ impulses), and its impulse list is formed only when asked for ([`Shaper::impulses`]:
/// the impulse table, exports), once. ZV-D³ over six modes (5⁶ = 15 625) fits.
pub const MAX_CONVOLVED_IMPULSES: usize = 1 << 16;
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
///
/// A convolution of more than [`MAX_IMPULSES`] impulses (up to [`MAX_CONVOLVED_IMPULSES`]) is
/// *factored*: its impulses are formed from the factors the first time [`Shaper::impulses`] is
/// called, and its duration, amplitude sum and centroid come from the factors (the duration of
/// a convolution is the sum of the factors' durations, its amplitude sum the product of theirs,
/// its centroid the sum of theirs).
#[derive(Debug, Clone)]
pub struct Shaper {
    /// The impulses; for a factored shaper formed from `factors` when first asked for.
    impulses: OnceLock<Vec<Impulse>>,
    /// The convolution factors' impulses (each a valid shaper's), or empty when the shaper is
    /// evaluated from its own impulses.
    factors: Vec<Vec<Impulse>>,
    /// Whether the shaper is factored (see [`Shaper`]): its summaries come from `factors`.
    factored: bool,
}

impl PartialEq for Shaper {
    fn eq(&self, other: &Self) -> bool {
        self.impulses() == other.impulses()
    }
}

/// The wire form of a shaper: `{ impulses: [{ time, amplitude }], duration }`, plus
/// `factors` for a factored shaper (see [`Shaper`]). `duration` and `factors` are written for
/// convenience and ignored when read.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShaperData {
    /// The impulses, sorted by time, first at 0.
    pub impulses: Vec<Impulse>,
    /// Time of the last impulse in seconds.
    #[serde(default)]
    pub duration: f64,
    /// For a convolution kept factored (more than [`MAX_IMPULSES`] impulses): its factors'
    /// impulses, each a shaper's, whose convolution `impulses` is. Absent otherwise.
    #[serde(default, skip_deserializing, skip_serializing_if = "Option::is_none")]
    pub factors: Option<Vec<Vec<Impulse>>>,
}

/// Whether `impulses` is the identity (one unit impulse), which a convolution leaves out.
fn is_unit(impulses: &[Impulse]) -> bool {
    matches!(impulses, [only] if only.amplitude == 1.0)
}

/// Impulses closer than this (relative to the shaper's duration) are merged into one.
const MERGE_TOLERANCE: f64 = 1e-12;

/// Sorts `impulses`, merges those at the same time (within [`MERGE_TOLERANCE`] of the span),
/// drops those of zero amplitude and shifts the first to t = 0. Errors: a merged amplitude
/// beyond [`MAX_AMPLITUDE`], or amplitudes that cancel to zero.
fn merge(impulses: Vec<Impulse>) -> Result<Vec<Impulse>> {
    let mut sorted = impulses;
    crate::sort::sort_by_f64_key(&mut sorted, |k| k.time);
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
    Ok(merged)
}

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
        Ok(Shaper::from_impulses(merge(impulses)?))
    }

    /// A shaper of already merged impulses.
    fn from_impulses(impulses: Vec<Impulse>) -> Shaper {
        Shaper {
            impulses: OnceLock::from(impulses),
            factors: Vec::new(),
            factored: false,
        }
    }

    /// Builds a shaper from its wire form.
    pub fn from_data(data: &ShaperData) -> Result<Self> {
        Shaper::new(data.impulses.clone())
    }

    /// The wire form, with the duration filled in.
    pub fn to_data(&self) -> ShaperData {
        ShaperData {
            impulses: self.impulses().to_vec(),
            duration: self.duration(),
            factors: self.factored.then(|| self.factors.clone()),
        }
    }

    /// The identity shaper: one unit impulse at t = 0 (the unshaped command).
    pub fn identity() -> Self {
        Shaper::from_impulses(vec![Impulse {
            time: 0.0,
            amplitude: 1.0,
        }])
    }

    /// The impulses, sorted by time, the first at t = 0. For a factored shaper (see
    /// [`Shaper`]) they are formed from the factors on the first call (up to
    /// [`MAX_CONVOLVED_IMPULSES`] products, merged as [`Shaper::new`] merges), then kept.
    pub fn impulses(&self) -> &[Impulse] {
        self.impulses.get_or_init(|| expand(&self.factors))
    }

    /// Whether the shaper is a convolution kept factored past [`MAX_IMPULSES`] (see
    /// [`Shaper`]): its impulses are formed only when [`Shaper::impulses`] is called.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Number of impulses (for a factored shaper, this forms them: see
    /// [`Shaper::impulses`]; [`Shaper::factor_impulses`] counts without forming them).
    pub fn len(&self) -> usize {
        self.impulses().len()
    }

    /// Impulses an evaluation walks: the factors' impulses summed (Σ nₖ), or the shaper's own
    /// count when it has no factors. Bounds the analyses' work ([`crate::vibration`]).
    pub fn factor_impulses(&self) -> usize {
        self.factors().map(<[Impulse]>::len).sum()
    }

    /// Impulses of the expanded shaper without forming them: [`Shaper::len`], or for a
    /// factored shaper the product Π nₖ of its factors' counts (an upper bound: merging
    /// coincident products can only lower it).
    pub fn expanded_len(&self) -> usize {
        if self.factored {
            return self.factors.iter().map(Vec::len).product();
        }
        self.len()
    }

    /// Always false: a shaper has at least one impulse.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Time of the last impulse, in seconds: the delay the shaper adds to a move. For a
    /// factored shaper the sum of the factors' durations: the last product's time, which its
    /// expanded list keeps unless another product falls within the merge tolerance (10⁻¹² of
    /// the span) of it — then the merged impulse keeps the earlier time, 10⁻¹² of the duration
    /// sooner at most.
    pub fn duration(&self) -> f64 {
        if self.factored {
            return self.factored_duration();
        }
        last_time(self.impulses())
    }

    /// Sum of the amplitudes (1 for a shaper that keeps the command's final value). For a
    /// factored shaper the product of the factors' sums.
    pub fn amplitude_sum(&self) -> f64 {
        if self.factored {
            return self.factored_sum();
        }
        sum_of(self.impulses())
    }

    /// Centroid delay Σ Aᵢtᵢ / Σ Aᵢ in seconds: the delay a slow ramp sees through the shaper
    /// (Kamel et al. eq. 10 without the plant's own 2ζ/ω). `None` when the amplitudes sum to 0,
    /// or when the sums overflow (amplitudes near f64::MAX). For a factored shaper the sum of
    /// the factors' centroids (the first moment of a convolution is the sum of the factors'
    /// normalised first moments times the product of their sums).
    pub fn centroid_delay(&self) -> Option<f64> {
        if self.factored {
            return self.factored_centroid();
        }
        centroid_of(self.impulses())
    }

    // The factored shaper's summaries, out of line: inlined at every caller of `duration`,
    // `amplitude_sum` and `centroid_delay` they cost the page's module kilobytes.
    #[inline(never)]
    fn factored_duration(&self) -> f64 {
        self.factors.iter().map(|f| last_time(f)).sum()
    }

    #[inline(never)]
    fn factored_sum(&self) -> f64 {
        self.factors.iter().map(|f| sum_of(f)).product()
    }

    #[inline(never)]
    fn factored_centroid(&self) -> Option<f64> {
        if self.factored_sum().abs() < 1e-15 {
            return None;
        }
        self.factors
            .iter()
            .map(|f| centroid_of(f))
            .sum::<Option<f64>>()
            .filter(|d| d.is_finite())
    }

    /// The convolution of two shapers: every pair of impulses multiplied, times added.
    /// Suppresses what either suppresses (Singer & Seering 1988 §2.3). Up to [`MAX_IMPULSES`]
    /// products the impulses are formed now; beyond, up to [`MAX_CONVOLVED_IMPULSES`], the
    /// result is factored (see [`Shaper`]). Errors: more products than
    /// [`MAX_CONVOLVED_IMPULSES`], or, for a factored result, amplitudes that could overflow
    /// when merged (Π Σ|aᵢ| beyond [`MAX_AMPLITUDE`]).
    pub fn convolve(&self, other: &Shaper) -> Result<Shaper> {
        // V of the product is the product of the factors' V (the transform of a convolution is
        // the product of the transforms; merging coincident impulses and dropping cancelled
        // ones change neither).
        let (factors, n) = self.product_factors(other)?;
        if n > MAX_IMPULSES {
            return Shaper::factored(factors);
        }
        let mut out = Vec::with_capacity(self.len() * other.len());
        for a in self.impulses() {
            for b in other.impulses() {
                out.push(Impulse {
                    time: a.time + b.time,
                    amplitude: a.amplitude * b.amplitude,
                });
            }
        }
        let mut shaper = Shaper::new(out)?;
        // Keep the factors when evaluating them is cheaper.
        if factors.len() > 1 && factors.iter().map(Vec::len).sum::<usize>() < shaper.len() {
            shaper.factors = factors;
        }
        Ok(shaper)
    }

    /// The factors of `self ⊛ other` (the identity's left out) and how many products they
    /// make; more than [`MAX_CONVOLVED_IMPULSES`] is an error.
    fn product_factors(&self, other: &Shaper) -> Result<(Vec<Vec<Impulse>>, usize)> {
        let factors: Vec<Vec<Impulse>> = self
            .factors()
            .chain(other.factors())
            .filter(|f| !is_unit(f))
            .map(<[Impulse]>::to_vec)
            .collect();
        let n = factors
            .iter()
            .try_fold(1_usize, |n, f| n.checked_mul(f.len()))
            .unwrap_or(usize::MAX);
        if n > MAX_CONVOLVED_IMPULSES {
            return Err(Error::TooLarge {
                field: "impulses".into(),
                value: n as f64,
                limit: MAX_CONVOLVED_IMPULSES as f64,
            });
        }
        Ok((factors, n))
    }

    /// The convolution of two shapers kept factored (see [`Shaper`]) whatever its size, up to
    /// [`MAX_CONVOLVED_IMPULSES`] products: the same shaper as [`Shaper::convolve`] (the same
    /// impulses once formed), analysed from its factors. Errors as [`Shaper::convolve`]'s.
    pub fn convolve_factored(&self, other: &Shaper) -> Result<Shaper> {
        let (factors, _) = self.product_factors(other)?;
        if factors.len() < 2 {
            // A single factor (the other was the identity) is that shaper.
            return Ok(factors
                .into_iter()
                .next()
                .map_or_else(Shaper::identity, Shaper::from_impulses));
        }
        Shaper::factored(factors)
    }

    /// A factored shaper of `factors` (each a valid shaper's impulses, at most
    /// [`MAX_CONVOLVED_IMPULSES`] products): refused when the merged amplitudes could overflow.
    fn factored(factors: Vec<Vec<Impulse>>) -> Result<Shaper> {
        let bound: f64 = factors
            .iter()
            .map(|f| f.iter().map(|imp| imp.amplitude.abs()).sum::<f64>())
            .product();
        if bound.is_nan() || bound > MAX_AMPLITUDE {
            return Err(Error::invalid(
                "impulses",
                format!(
                    "the convolution's amplitudes could exceed {MAX_AMPLITUDE:e} \
                     (the product of the factors' Σ|amplitude| is {bound:e})"
                ),
            ));
        }
        Ok(Shaper {
            impulses: OnceLock::new(),
            factors,
            factored: true,
        })
    }

    /// The impulse sequences whose residual vibrations multiply to this shaper's: its
    /// convolution factors (see [`Shaper`]), or its own impulses alone.
    pub fn factors(&self) -> impl Iterator<Item = &[Impulse]> {
        let own = self.factors.is_empty().then(|| self.impulses());
        own.into_iter()
            .chain(self.factors.iter().map(Vec::as_slice))
    }

    /// The same shaper with all times multiplied by `factor` (> 0): a shaper for a mode at
    /// frequency f, scaled by f/f', suits frequency f' when ζ = 0.
    pub fn scaled_in_time(&self, factor: f64) -> Result<Shaper> {
        crate::error::positive("factor", factor)?;
        if self.factored {
            let mut scaled = self.factors.iter().map(|f| {
                Shaper::new(
                    f.iter()
                        .map(|imp| Impulse {
                            time: imp.time * factor,
                            amplitude: imp.amplitude,
                        })
                        .collect(),
                )
            });
            let first = scaled.next().unwrap_or_else(|| Ok(Shaper::identity()))?;
            return scaled.try_fold(first, |acc, f| acc.convolve(&f?));
        }
        Shaper::new(
            self.impulses()
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
        if self.factored {
            let mut parts = self
                .factors
                .iter()
                .map(|f| Shaper::new(f.clone())?.normalized());
            let first = parts.next().unwrap_or_else(|| Ok(Shaper::identity()))?;
            return parts.try_fold(first, |acc, f| acc.convolve(&f?));
        }
        Shaper::new(
            self.impulses()
                .iter()
                .map(|imp| Impulse {
                    time: imp.time,
                    amplitude: imp.amplitude / sum,
                })
                .collect(),
        )
    }
}

/// The time of the last impulse (0 for none).
fn last_time(impulses: &[Impulse]) -> f64 {
    impulses.last().map_or(0.0, |imp| imp.time)
}

/// Σ Aᵢ.
fn sum_of(impulses: &[Impulse]) -> f64 {
    impulses.iter().map(|imp| imp.amplitude).sum()
}

/// Σ Aᵢtᵢ / Σ Aᵢ, `None` when the sum is (near) zero or the result not finite.
fn centroid_of(impulses: &[Impulse]) -> Option<f64> {
    let sum = sum_of(impulses);
    if sum.abs() < 1e-15 {
        return None;
    }
    let delay = impulses
        .iter()
        .map(|imp| imp.amplitude * imp.time)
        .sum::<f64>()
        / sum;
    delay.is_finite().then_some(delay)
}

/// The impulses of the convolution of `factors`: every product, merged as [`Shaper::new`]
/// merges. A factored shaper was checked when made so that merging cannot overflow; should it
/// still fail (amplitudes that cancel exactly), the unmerged products are returned rather than
/// nothing.
fn expand(factors: &[Vec<Impulse>]) -> Vec<Impulse> {
    let mut out = vec![Impulse {
        time: 0.0,
        amplitude: 1.0,
    }];
    for f in factors {
        let mut next = Vec::with_capacity(out.len() * f.len());
        for a in &out {
            for b in f {
                next.push(Impulse {
                    time: a.time + b.time,
                    amplitude: a.amplitude * b.amplitude,
                });
            }
        }
        out = next;
    }
    merge(out.clone()).unwrap_or_else(|_| {
        crate::sort::sort_by_f64_key(&mut out, |k| k.time);
        out
    })
}
