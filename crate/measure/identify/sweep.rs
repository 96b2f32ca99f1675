//! Stage 0 for raw recordings: is the excitation a sweep, and which band does it cover?
//!
//! Klipper's resonance test (klippy/extras/resonance_tester.py, `VibrationPulseTestGenerator.
//! gen_test`, run by `ResonanceTestExecutor.run_test`) drives the toolhead with an acceleration
//! of ±`accel_per_hz`·f that changes sign every quarter period of f, f rising by `hz_per_sec`
//! per second from `freq_start` to `freq_end`: a square wave whose frequency rises linearly in
//! time. Newer versions (`SweepingVibrationsTestGenerator.gen_test`) add a slow ±`sweeping_accel`
//! square wave of period `sweeping_period` (≈ 0.8 Hz and its odd harmonics). What the sensor
//! sees at any moment is dominated by the response at the current drive frequency f(t).
//!
//! The sweep is read from the data itself, not from the test's parameters: short Hann frames
//! (about 1 s, a quarter-frame hop; shorter, down to 1/16 s, for a record under 4 s or a sweep
//! they do not find: a fast one), the bin of each that stands highest over its own usual log
//! power through the record (above the second bin, where the slow component and drift sit;
//! a mode rung all through the test is the strongest bin but no sweep; a harmonic of the
//! drive gives way to the fundamental under it), interpolated in log power, and a straight
//! line f(t) = f₀ + r·t fitted robustly (Theil–Sen slope, then least squares over the frames
//! within two bins of it). A recording is a sweep when the line holds for most frames and
//! spans at least eight frame bins (four of the shorter frames' wider bins). Its band is the
//! line over the inlying frames, widened by half a frame's worth of sweep at each end (a
//! frame's ridge is the mean frequency over the frame).
//!
//! Exponential sweeps too (f = f₀·e^(βt): a shaker's logarithmic sine sweep, octaves per
//! minute): the same robust line through ln f(t), kept when it holds for more frames than the
//! straight one; its late frames, which smear β·f·T each, are allowed a quarter of that, and
//! its top is read again on shorter frames. Until 2026-12-06 only the straight line was
//! fitted: 5 → 97 Hz in 4 s came out as a linear sweep over 5–51 Hz, and the modes past it
//! were lost (benches/reference/sweep_chirps.py, docs/measured-data.md).
//!
//! Why it matters: a Welch average of a sweep with segments shorter than the record is lumpy
//! (each segment sees a few hertz of the sweep), and outside the swept band the PSD is noise and
//! harmonics, not the modal response. The whole record's periodogram of a sweep is
//! |H(f)|²·|A(f)|², with |A(f)|² smooth inside the band (stationary phase: every frequency is
//! passed once, for a time ∝ 1/r, at an amplitude ∝ f), so identify fits that periodogram,
//! inside the band.

use crate::measure::fft::{Complex, Fft};
use crate::measure::psd::{window, WindowKind};
use serde::Serialize;

/// How a sweep's frequency moves with time (JS: `'linear'` | `'exponential'`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SweepLaw {
    /// f(t) = f₀ + r·t: Klipper's resonance test (`hz_per_sec`), a linear chirp.
    Linear,
    /// f(t) = f₀·e^(β·t): a logarithmic (exponential) chirp, a shaker's usual sine sweep in
    /// octaves per minute; its rate β·f grows with the frequency.
    Exponential,
}

/// A sweep found in a recording (JS: `{ bandHz, rateHzPerS, law }`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct Sweep {
    /// Lowest and highest frequency swept, Hz.
    pub band_hz: [f64; 2],
    /// Sweep rate, Hz/s (its magnitude): the rate of a linear sweep; an exponential sweep's
    /// at the band's geometric centre √(f_lo·f_hi) (see [`Sweep::rate_at`]).
    pub rate_hz_per_s: f64,
    /// Linear or exponential.
    pub law: SweepLaw,
    /// Seen over part of the record only, the rest under the sensor's noise (see
    /// `Reading::Part`): below the band there is nothing but noise to read.
    #[serde(skip)]
    pub(crate) partial: bool,
}

impl Sweep {
    /// The rate at which the sweep passes `frequency_hz`, Hz/s: `rate_hz_per_s` for a linear
    /// sweep, ∝ the frequency for an exponential one.
    pub fn rate_at(&self, frequency_hz: f64) -> f64 {
        match self.law {
            SweepLaw::Linear => self.rate_hz_per_s,
            SweepLaw::Exponential => {
                self.rate_hz_per_s * frequency_hz / (self.band_hz[0] * self.band_hz[1]).sqrt()
            }
        }
    }
}

/// Each frame's power spectrum (Hann, mean removed; bins `0..len/2`) and its power above the
/// second bin, handed to `each` in time order with the frame's centre, s.
fn frames(signal: &[f64], fs: f64, len: usize, mut each: impl FnMut(f64, &[f64], f64)) {
    let hop = (len / 4).max(1);
    let w = window(WindowKind::Hann, len, false, 0.0);
    let mut plan = Fft::new(len);
    let mut data = vec![Complex::default(); len];
    let mut p = vec![0.0; len / 2];
    let mut start = 0;
    while start + len <= signal.len() {
        let seg = &signal[start..start + len];
        let mean = seg.iter().sum::<f64>() / len as f64;
        for (d, (v, wi)) in data.iter_mut().zip(seg.iter().zip(&w)) {
            *d = Complex::new((v - mean) * wi, 0.0);
        }
        plan.forward(&mut data);
        for (pk, z) in p.iter_mut().zip(&data) {
            *pk = z.norm_sqr();
        }
        let total: f64 = p[2..].iter().sum();
        each((start as f64 + 0.5 * len as f64) / fs, &p, total);
        start += hop;
    }
}

/// The ridge of each frame: (frame centre s, frequency Hz), frames with power. The ridge is
/// the bin standing highest over its own usual level through the record, not the strongest
/// bin: a lightly damped mode rung all through the test (by the slow sweep's steps, the
/// drive's harmonics, the start) is the strongest bin of most frames where the drive is far
/// from it — a 59.75 Hz, ζ 0.02 mode swept 40–60 Hz at 2 Hz/s, or a 140 Hz mode past a 133 Hz
/// end, hid the sweep — while the drive passes each bin in a few frames and stands there tens
/// of dB over the bin's usual level. Steady lines (a mode's ringing, the slow sweep's
/// harmonics, mains hum) are level with their own usual level and drop out. The usual level is
/// the lower quintile of the bin's log power over the frames (at most `MAX_LEVEL_FRAMES`,
/// fewer for long frames, evenly spread), not its mean: in a narrow sweep the drive (with
/// its main lobe's ±2 bins) is near each bin for much of the record and raised the mean to
/// its own level (23–32.6 Hz at 2 Hz/s, 0.64 s frames: two thirds of the time), and the
/// third harmonic stood higher.
/// A bin at a fraction of the top's frequency may still be the fundamental (`fundamental`).
/// The peak is then interpolated in log power on the frame's own spectrum.
fn ridge(signal: &[f64], fs: f64, len: usize) -> Vec<(f64, f64)> {
    let half = len / 2;
    let count = (signal.len().saturating_sub(len) / (len / 4).max(1) + 1).max(1);
    let most = (MAX_LEVEL_VALUES / half.max(1)).clamp(16, MAX_LEVEL_FRAMES);
    let stride = count.div_ceil(most);
    let mut logs: Vec<f32> = Vec::new();
    let mut i = 0usize;
    frames(signal, fs, len, |_, p, _| {
        if i.is_multiple_of(stride) {
            logs.extend(p.iter().map(|v| v.max(1e-300).ln() as f32));
        }
        i += 1;
    });
    let kept = logs.len() / half.max(1);
    let mut column = vec![0f32; kept];
    let level: Vec<f64> = (0..half)
        .map(|k| {
            for (c, j) in column.iter_mut().zip(0..kept) {
                *c = logs[j * half + k];
            }
            column.sort_by(f32::total_cmp);
            column.get(kept / 5).map_or(0.0, |&v| f64::from(v))
        })
        .collect();
    let mut out = Vec::new();
    frames(signal, fs, len, |centre, p, total| {
        let lift = |k: usize| p[k].max(1e-300).ln() - level[k];
        if let Some(top) = (3..len / 2 - 1).max_by(|&a, &b| lift(a).total_cmp(&lift(b))) {
            let k = fundamental(p, top, &lift);
            let (ym, y0, yp) = (
                p[k - 1].max(1e-300).ln(),
                p[k].max(1e-300).ln(),
                p[k + 1].max(1e-300).ln(),
            );
            let den = ym - 2.0 * y0 + yp;
            let delta = if den < 0.0 {
                (0.5 * (ym - yp) / den).clamp(-0.5, 0.5)
            } else {
                0.0
            };
            out.push((centre, (k as f64 + delta) * fs / len as f64, total));
        }
    });
    // Frames with less than 1 % of the median power are idle (before or after the test).
    let mut powers: Vec<f64> = out.iter().map(|f| f.2).collect();
    powers.sort_by(f64::total_cmp);
    let median = powers.get(powers.len() / 2).copied().unwrap_or(0.0);
    out.into_iter()
        .filter(|f| f.2 >= 0.01 * median)
        .map(|f| (f.0, f.1))
        .collect()
}

/// The most frames a bin's usual level is read from (evenly spread over the record).
const MAX_LEVEL_FRAMES: usize = 256;
/// The most log powers kept for the levels (4 MB of f32): a 25.6 kHz recording's 16 384-bin
/// frames read their levels from 64 frames, a 3.2 kHz one's 2048-bin frames from 256.
const MAX_LEVEL_VALUES: usize = 1 << 20;

/// The drive's fundamental for a frame whose highest-standing bin is `top`: the bin nearest
/// `top`/d (d = 5, 4, 3, 2, the lowest first; ±1 bin) that holds more power than `top` and
/// stands at least half as high over its usual level, else `top`. A square-wave drive's third
/// harmonic carries a ninth of the fundamental's power but can stand higher over its bins'
/// level, spread over three times as many bins as the fundamental dwells in.
fn fundamental(p: &[f64], top: usize, lift: &impl Fn(usize) -> f64) -> usize {
    let raise = lift(top);
    for d in (2..=5).rev() {
        let c = (top as f64 / d as f64).round() as usize;
        if c < 4 || c + 1 >= p.len() {
            continue;
        }
        let j = (c - 1..=c + 1)
            .max_by(|&a, &b| p[a].total_cmp(&p[b]))
            .unwrap_or(c);
        if p[j] > p[top] && lift(j) >= 0.5 * raise {
            return j;
        }
    }
    top
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Least squares line through points: (intercept, slope).
fn line(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = points.len() as f64;
    let (st, sf) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mt, mf) = (st / n, sf / n);
    let (sxx, sxy) = points.iter().fold((0.0, 0.0), |(a, b), p| {
        (a + (p.0 - mt).powi(2), b + (p.0 - mt) * (p.1 - mf))
    });
    (sxx > 0.0).then(|| (mf - sxy / sxx * mt, sxy / sxx))
}

/// Finds a linear sweep in `signal` sampled at `fs` (see the module docs); None when the
/// excitation is not one (noise, a hit, a record shorter than 4 frames of 1/16 s).
///
/// Frames of about a second first; a record shorter than 4 such frames (13 at the quarter
/// hop), or one where they find no sweep, is read again with frames half as long, down to
/// 1/16 s while the record holds 4 of them. A fast sweep is only seen that
/// way: 20–120 Hz in 2 s passes 50 Hz within a one-second frame, whose ridge is then the
/// mean of a smear, and a record of 2 s has too few such frames for a line. Shorter frames
/// have wider bins (16 Hz at 1/16 s), which a fast sweep's span of dozens of bins allows; a
/// line through them must span 4 of them (8 of the first frames' bins): 15 Hz swept in
/// 1.7 s spans 4.9 bins of the 0.32 s frames that record holds 18 of.
pub(super) fn detect_sweep(signal: &[f64], fs: f64) -> Option<Sweep> {
    let mut ridges = Ridges {
        signal,
        fs,
        kept: Vec::new(),
    };
    detect_with(&mut ridges, Reading::Whole).or_else(|| detect_with(&mut ridges, Reading::Part))
}

/// Each frame length's ridge ([`ridge`]), computed once for both readings (a recording that
/// is no sweep is read twice at every length: its frames' FFTs were most of that).
struct Ridges<'a> {
    signal: &'a [f64],
    fs: f64,
    kept: Vec<(usize, Vec<(f64, f64)>)>,
}

impl Ridges<'_> {
    fn frames(&mut self, len: usize) -> &[(f64, f64)] {
        let at = match self.kept.iter().position(|(l, _)| *l == len) {
            Some(i) => i,
            None => {
                self.kept.push((len, ridge(self.signal, self.fs, len)));
                self.kept.len() - 1
            }
        };
        &self.kept[at].1
    }
}

/// How much of the record a sweep must be seen over (see [`Reading`] and `detect_sweep`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reading {
    /// The line holds for most frames of the record (Theil–Sen through all of them).
    Whole,
    /// A sweep seen over part of the record only, the rest of its frames noise: the drive
    /// under the sensor's noise until it nears a mode (a low-pass plant swept from 5 Hz with
    /// the drive ∝ f: 0–3.5 s of a 6.1 s logarithmic sweep to 116 Hz read noise, and the
    /// frames past a sharp mode its ringing; benches/reference/sweep_chirps.py, seed 3). Tried
    /// only when the whole reading finds no sweep at any frame length (its finds stay as they
    /// were), with a line of consensus ([`consensus_line`]) held densely by at least a
    /// quarter of the frames.
    Part,
}

fn detect_with(ridges: &mut Ridges, reading: Reading) -> Option<Sweep> {
    let (signal, fs) = (ridges.signal, ridges.fs);
    let first = (fs.round() as usize).next_power_of_two().clamp(64, 1 << 16);
    let last = ((fs / 16.0).round() as usize).next_power_of_two().max(64);
    let mut len = first;
    loop {
        if signal.len() >= 4 * len {
            let span_bins = if len == first { 8.0 } else { 4.0 };
            if let Some(s) = sweep_with_frames(ridges, len, span_bins, reading) {
                return Some(match s.law {
                    SweepLaw::Linear => s,
                    SweepLaw::Exponential => exponential_top(ridges, len, last, s, reading),
                });
            }
        }
        if len / 2 < last {
            return None;
        }
        len /= 2;
    }
}

/// An exponential sweep found on frames of `len` samples, its top read again on shorter frames
/// (down to `last` samples): its rate grows with the frequency, so the frames that resolve
/// its slow start smear its fast end (5 → 258 Hz in 6 s passes 170 Hz/s at the top, 220 Hz in
/// a 1.3 s frame, whose strongest bin then lies well under the sweep: the band ended at
/// 220 Hz), and halving the frame halves the smear. The highest top of those that find the
/// same law at the same growth (within 15 %) is kept; the start stays the long frames'.
fn exponential_top(
    ridges: &mut Ridges,
    len: usize,
    last: usize,
    found: Sweep,
    reading: Reading,
) -> Sweep {
    let growth = |s: &Sweep| s.rate_hz_per_s / (s.band_hz[0] * s.band_hz[1]).sqrt();
    let mut out = found;
    let mut shorter = len / 2;
    while shorter >= last && ridges.signal.len() >= 4 * shorter {
        if let Some(s) = sweep_with_frames(ridges, shorter, 4.0, reading) {
            if s.law == SweepLaw::Exponential
                && (growth(&s) / growth(&found) - 1.0).abs() <= 0.15
                && s.band_hz[1] > out.band_hz[1]
            {
                out.band_hz[1] = s.band_hz[1];
            }
        }
        shorter /= 2;
    }
    out.rate_hz_per_s = growth(&found) * (out.band_hz[0] * out.band_hz[1]).sqrt();
    out
}

/// The sweep as frames of `len` samples see it, spanning at least `span_bins` of their bins
/// (see `detect_sweep`): the law whose line holds for more frames, linear on a tie (a narrow
/// exponential sweep is nearly linear, and either reads it). Read whole, the line must hold
/// for 60 % of the frames; read in part, for a quarter of them and 60 % of those between its
/// first and last.
fn sweep_with_frames(
    ridges: &mut Ridges,
    len: usize,
    span_bins: f64,
    reading: Reading,
) -> Option<Sweep> {
    let fs = ridges.fs;
    let frames = ridges.frames(len);
    let n = frames.len();
    if n < 8 {
        return None;
    }
    let bin = fs / len as f64;
    let frame_s = len as f64 / fs;
    let fit_law = |law| match reading {
        Reading::Whole => law_line(frames, law, bin, frame_s),
        Reading::Part => consensus_line(frames, law, bin, frame_s),
    };
    let linear = fit_law(SweepLaw::Linear);
    let exponential = fit_law(SweepLaw::Exponential);
    let held = |l: &Option<LawLine>| l.as_ref().map_or(0, |l| l.within_two_bins);
    let (law, fit) = if held(&exponential) > held(&linear) + (n / 20).max(1) {
        (SweepLaw::Exponential, exponential?)
    } else {
        (SweepLaw::Linear, linear?)
    };
    let held_enough = match reading {
        Reading::Whole => fit.inliers as f64 >= 0.6 * n as f64,
        Reading::Part => {
            let between = frames
                .iter()
                .filter(|f| f.0 >= fit.first_s && f.0 <= fit.last_s)
                .count();
            4 * fit.inliers >= n && fit.inliers as f64 >= 0.6 * between as f64
        }
    };
    if fit.inliers < 8 || !held_enough {
        return None;
    }
    // The line over the inlying frames, widened by half a frame's worth of sweep at each end.
    // A sweep seen in part goes on past its last frame over the noise while the record does
    // (a sharp mode's ringing, then the response under the noise: a low-pass plant past its
    // mode), up to as long again as it was seen: its band reaches past the mode it found.
    let last_s = match reading {
        Reading::Whole => fit.last_s,
        Reading::Part => frames.last().map_or(fit.last_s, |f| {
            f.0.clamp(fit.last_s, 2.0 * fit.last_s - fit.first_s)
        }),
    };
    let (ga, gb) = (
        fit.intercept + fit.slope * fit.first_s,
        fit.intercept + fit.slope * last_s,
    );
    let widen = (0.5 * frame_s * fit.slope).abs();
    let (lo, hi) = (ga.min(gb) - widen, ga.max(gb) + widen);
    let band = match law {
        SweepLaw::Linear => [lo, hi],
        SweepLaw::Exponential => [lo.exp(), hi.exp()],
    };
    let band = [band[0], band[1].min(0.45 * fs)];
    if band[1] - band[0] < span_bins * bin || band[0] <= 0.0 {
        return None;
    }
    let rate = match law {
        SweepLaw::Linear => fit.slope.abs(),
        SweepLaw::Exponential => fit.slope.abs() * (band[0] * band[1]).sqrt(),
    };
    Some(Sweep {
        band_hz: band,
        rate_hz_per_s: rate,
        law,
        partial: reading == Reading::Part,
    })
}

/// A robust line g(f(t)) = intercept + slope·t through the ridge's frames, g the identity for
/// a linear sweep and ln for an exponential one: Theil–Sen (the median of the pairwise slopes,
/// over at most 400 evenly spread frames: a long record would otherwise make millions of
/// pairs), the frames within two bins of it in frequency as inliers, then least squares over
/// them. An exponential sweep's frames are allowed a quarter of what the sweep passes in a
/// frame more (β·f·T/4, T the frame's length): its rate grows with f, and a frame late in a
/// wide one smears tens of hertz (5 → 300 Hz in 10 s passes 80 Hz/s at 200 Hz), its
/// strongest bin anywhere in the middle of the smear. The laws are compared on the frames
/// within two bins alone (the allowance would favour the exponential law on a linear sweep).
struct LawLine {
    intercept: f64,
    slope: f64,
    /// How many frames lie near the robust line (the line's own allowance).
    inliers: usize,
    /// How many lie within two bins of it.
    within_two_bins: usize,
    /// The first and last inlying frames' centres, s.
    first_s: f64,
    last_s: f64,
}

/// A law's map of frequency (identity or ln), or its inverse.
type Map = fn(f64) -> f64;

/// The frames (time, g(f)) with g the law's map (identity or ln), frames without a positive
/// frequency left out, and the map's inverse.
fn mapped_frames(frames: &[(f64, f64)], law: SweepLaw) -> (Vec<(f64, f64)>, Map) {
    let (g, inverse): (Map, Map) = match law {
        SweepLaw::Linear => (|f| f, |g| g),
        SweepLaw::Exponential => (f64::ln, f64::exp),
    };
    let mapped = frames
        .iter()
        .filter(|p| p.1 > 0.0)
        .map(|p| (p.0, g(p.1)))
        .collect();
    (mapped, inverse)
}

fn law_line(frames: &[(f64, f64)], law: SweepLaw, bin: f64, frame_s: f64) -> Option<LawLine> {
    let (mapped, inverse) = mapped_frames(frames, law);
    let n = mapped.len();
    if n < 2 {
        return None;
    }
    let picked: Vec<(f64, f64)> = mapped.iter().step_by(n.div_ceil(400)).copied().collect();
    let p = picked.len();
    let mut slopes = Vec::with_capacity(p * (p - 1) / 2);
    for i in 0..p {
        for j in i + 1..p {
            slopes.push((picked[j].1 - picked[i].1) / (picked[j].0 - picked[i].0));
        }
    }
    let r0 = median(&mut slopes);
    let mut offsets: Vec<f64> = mapped.iter().map(|p| p.1 - r0 * p.0).collect();
    let b0 = median(&mut offsets);
    let smear = match law {
        SweepLaw::Linear => 0.0,
        SweepLaw::Exponential => 0.25 * r0.abs() * frame_s,
    };
    let off = |p: &(f64, f64)| {
        let f = inverse(b0 + r0 * p.0);
        ((inverse(p.1) - f).abs(), f)
    };
    let strict: Vec<(f64, f64)> = mapped
        .iter()
        .copied()
        .filter(|p| off(p).0 <= 2.0 * bin)
        .collect();
    let near: Vec<(f64, f64)> = mapped
        .iter()
        .copied()
        .filter(|p| {
            let (d, f) = off(p);
            d <= 2.0 * bin + smear * f
        })
        .collect();
    let (intercept, slope) = line(&near)?;
    Some(LawLine {
        intercept,
        slope,
        inliers: near.len(),
        within_two_bins: strict.len(),
        first_s: near.iter().map(|p| p.0).fold(f64::INFINITY, f64::min),
        last_s: near.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max),
    })
}

/// The law's line held by the most frames, for a sweep seen over part of the record
/// ([`Reading::Part`]): Theil–Sen breaks down when most frames are noise (its median slope is
/// the noise's), so candidate lines are drawn through pairs of frames near in time (2, 4 and 8
/// hops apart, from at most 300 evenly spread first frames), each scored by the frames within
/// two bins of it (plus the exponential law's smear, as [`law_line`]). The best one's inliers
/// are split where two follow each other more than half a frame apart (one frame of the
/// quarter hop missed), the largest run is kept (noise frames that fall near the line's
/// extension are not the sweep: with a frame's length a 1 kHz recording's band reached down
/// to 12.5 Hz from a sweep seen from 22 Hz), and the line
/// is fitted to it by least squares and its frames counted again.
fn consensus_line(frames: &[(f64, f64)], law: SweepLaw, bin: f64, frame_s: f64) -> Option<LawLine> {
    let (mapped, inverse) = mapped_frames(frames, law);
    let n = mapped.len();
    if n < 8 {
        return None;
    }
    let near = |b: f64, r: f64, p: &(f64, f64), smear_of: f64| {
        let f = inverse(b + r * p.0);
        let smear = match law {
            SweepLaw::Linear => 0.0,
            SweepLaw::Exponential => 0.25 * smear_of.abs() * frame_s,
        };
        (inverse(p.1) - f).abs() <= 2.0 * bin + smear * f
    };
    let mut best: Option<(usize, f64, f64)> = None;
    for i in (0..n).step_by(n.div_ceil(300)) {
        for d in [2, 4, 8] {
            let Some(q) = mapped.get(i + d) else { continue };
            let p = mapped[i];
            if q.0 <= p.0 {
                continue;
            }
            let r = (q.1 - p.1) / (q.0 - p.0);
            let b = p.1 - r * p.0;
            let count = mapped.iter().filter(|m| near(b, r, m, r)).count();
            if best.is_none_or(|(c, _, _)| count > c) {
                best = Some((count, b, r));
            }
        }
    }
    let (_, b, r) = best?;
    let inliers: Vec<(f64, f64)> = mapped
        .iter()
        .copied()
        .filter(|m| near(b, r, m, r))
        .collect();
    // The largest run of inliers with no gap longer than a frame.
    let mut runs: Vec<&[(f64, f64)]> = Vec::new();
    let mut start = 0;
    for k in 1..=inliers.len() {
        if k == inliers.len() || inliers[k].0 - inliers[k - 1].0 > 0.5 * frame_s + 1e-9 {
            runs.push(&inliers[start..k]);
            start = k;
        }
    }
    let run = runs.into_iter().max_by_key(|r| r.len())?;
    let (intercept, slope) = line(run)?;
    let (t0, t1) = (run[0].0, run[run.len() - 1].0);
    let within: Vec<&(f64, f64)> = mapped
        .iter()
        .filter(|m| m.0 >= t0 && m.0 <= t1 && near(intercept, slope, m, slope))
        .collect();
    let strict = within
        .iter()
        .filter(|m| (inverse(m.1) - inverse(intercept + slope * m.0)).abs() <= 2.0 * bin)
        .count();
    Some(LawLine {
        intercept,
        slope,
        inliers: within.len(),
        within_two_bins: strict,
        first_s: t0,
        last_s: t1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square wave whose frequency rises from 20 to 80 Hz at 4 Hz/s (Klipper's kind of test):
    /// the band and the rate come back; white noise and a steady tone are not sweeps.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn finds_a_linear_sweep_and_nothing_else() {
        let fs = 2000.0;
        let (f0, r, dur) = (20.0, 4.0, 15.0);
        let x = square_sweep(f0, r, dur, fs);
        let s = detect_sweep(&x, fs).unwrap();
        assert_eq!(s.law, SweepLaw::Linear, "{s:?}");
        assert!((s.rate_hz_per_s - r).abs() < 0.05 * r, "{s:?}");
        assert!((s.band_hz[0] - f0).abs() < 2.0, "{s:?}");
        assert!((s.band_hz[1] - (f0 + r * dur)).abs() < 2.0, "{s:?}");
        // A tone (no slope) and noise (no line).
        let tone = tone(x.len(), fs);
        assert!(detect_sweep(&tone, fs).is_none());
        assert!(detect_sweep(&noise(x.len(), 12345), fs).is_none());
        // The sweep under a steady line ~27 dB over its fundamental (a lightly damped mode rung
        // all through the test): the strongest bin of every frame is the line; the sweep is
        // still found.
        let rung: Vec<f64> = x
            .iter()
            .zip(&tone)
            .map(|(s, t)| s + 30.0 * 80.0 * t)
            .collect();
        let s = detect_sweep(&rung, fs).unwrap();
        assert!((s.rate_hz_per_s - r).abs() < 0.05 * r, "{s:?}");
        assert!((s.band_hz[1] - (f0 + r * dur)).abs() < 2.0, "{s:?}");
    }

    /// A 37 Hz tone of `n` samples at `fs`.
    fn tone(n: usize, fs: f64) -> Vec<f64> {
        (0..n)
            .map(|i| (2.0 * std::f64::consts::PI * 37.0 * i as f64 / fs).sin())
            .collect()
    }

    /// `n` samples of uniform noise (a fixed linear congruential sequence from `seed`).
    fn noise(n: usize, mut state: u64) -> Vec<f64> {
        (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    /// Klipper's drive as a square wave of amplitude ∝ f whose frequency rises from `f0` at
    /// `r` Hz/s for `dur` s, sampled at `fs`.
    fn square_sweep(f0: f64, r: f64, dur: f64, fs: f64) -> Vec<f64> {
        (0..(dur * fs) as usize)
            .map(|i| {
                let t = i as f64 / fs;
                let f = f0 + r * t;
                f * (2.0 * std::f64::consts::PI * (f0 * t + 0.5 * r * t * t))
                    .sin()
                    .signum()
            })
            .collect()
    }

    /// An exponential sweep, f = f₀·e^(βt) (a square wave of amplitude ∝ f from 10 to 400 Hz
    /// in 6 s, and a sine of constant amplitude from 5 to 200 Hz in 2.5 s): the law, the band
    /// and the growth β come back (the rate at f is β·f). A straight line f(t) held for the
    /// slow start alone: 10 → 400 Hz was read as a linear sweep over 10–120 Hz.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn finds_an_exponential_sweep() {
        let fs = 3200.0;
        for (f0, f1, dur, square) in [(10.0, 400.0, 6.0, true), (5.0, 200.0, 2.5, false)] {
            let beta = f64::ln(f1 / f0) / dur;
            let x: Vec<f64> = (0..(dur * fs) as usize)
                .map(|i| {
                    let t = i as f64 / fs;
                    let s =
                        (2.0 * std::f64::consts::PI * f0 * ((beta * t).exp() - 1.0) / beta).sin();
                    if square {
                        f0 * (beta * t).exp() * s.signum()
                    } else {
                        s
                    }
                })
                .collect();
            let s = detect_sweep(&x, fs).unwrap();
            assert_eq!(s.law, SweepLaw::Exponential, "{s:?}");
            assert!((s.band_hz[0] / f0 - 1.0).abs() < 0.3, "{s:?}");
            assert!((s.band_hz[1] / f1 - 1.0).abs() < 0.05, "{s:?}");
            // Within 8 %: a frame late in the sweep smears tens of hertz, its strongest bin
            // leaning to the side where the drive puts more power per hertz (only √r, the
            // width of the excitation's ripple, is read from the rate: 4 % in √r).
            for f in [20.0, 100.0] {
                assert!(
                    (s.rate_at(f) / (beta * f) - 1.0).abs() < 0.08,
                    "{s:?}: β {beta}"
                );
            }
        }
    }

    /// Short records: 20 → 120 Hz in 2 s (a fast sweep: frames of a second would each smear
    /// 50 Hz, and the record holds fewer than four of them) and 23 → 32.6 Hz at 2 Hz/s in
    /// 4.8 s (a narrow sweep whose fundamental dwells in each of the 0.64 s frames' bins for
    /// a sixth of the record: the mean level of those bins is the drive's own, and the third
    /// harmonic, spread over three times the bins, stood higher over its mean: the ridge
    /// jumped to 77–88 Hz in mid-record). Two seconds of noise or of a tone are no sweep.
    #[wasm_bindgen_test::wasm_bindgen_test(unsupported = test)]
    fn finds_short_fast_and_short_narrow_sweeps() {
        let fs = 3200.0;
        let s = detect_sweep(&square_sweep(20.0, 50.0, 2.0, fs), fs).unwrap();
        assert_eq!(s.law, SweepLaw::Linear, "{s:?}");
        assert!((s.rate_hz_per_s - 50.0).abs() < 0.05 * 50.0, "{s:?}");
        assert!((s.band_hz[0] - 20.0).abs() < 4.0, "{s:?}");
        assert!((s.band_hz[1] - 120.0).abs() < 4.0, "{s:?}");
        let s = detect_sweep(&square_sweep(23.0, 2.0, 4.8, fs), fs).unwrap();
        assert!((s.rate_hz_per_s - 2.0).abs() < 0.1 * 2.0, "{s:?}");
        assert!((s.band_hz[0] - 23.0).abs() < 1.5, "{s:?}");
        assert!((s.band_hz[1] - 32.6).abs() < 1.5, "{s:?}");
        let n = (2.0 * fs) as usize;
        assert!(detect_sweep(&tone(n, fs), fs).is_none());
        assert!(detect_sweep(&noise(n, 777), fs).is_none());
    }
}
