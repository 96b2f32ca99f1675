//! Klipper's spectrum files, and several runs combined.
//!
//! Klipper (`klippy/extras/shaper_calibrate.py`, `ShaperCalibrate.save_calibration_data`)
//! writes two spectrum files, both with the header `freq,psd_x,psd_y,psd_z,psd_xyz`, one row per
//! Welch bin below 200 Hz (`MAX_FREQ`), the frequency as `%.1f` and each PSD as `%.3e`:
//!
//! - `resonances_<axis>_<name>.csv` (`TEST_RESONANCES`, `klippy/extras/resonance_tester.py`):
//!   the PSD as computed ([`Normalization::None`]).
//! - `calibration_data_<axis>_<name>.csv` (`SHAPER_CALIBRATE`): the header goes on with
//!   `,shapers:` and one `,<name>(<freq>)` per fitted shaper; each row with an empty field and
//!   each shaper's remaining-vibration ratio at that frequency (`%.3f`). `SHAPER_CALIBRATE`
//!   calls `CalibrationData.normalize_to_frequencies` before writing, so these PSDs are divided
//!   by f + 0.1 and tapered below 10 Hz ([`Normalization::Klipper`], see [`klipper_normalize`]). `scripts/calibrate_shaper.py`
//!   (`parse_log`) decides the same way: a header naming `mzv` (a shaper) is taken as already
//!   normalised, any other is normalised on reading.
//!
//! Columns after `psd_xyz` and before `shapers:` (forks add e.g. `accel_per_hz`) are kept as
//! [`SpectrumFile::extra`]. Klipper's raw accelerometer files (`#time,accel_x,accel_y,accel_z`)
//! become a spectrum through [`klipper_spectrum`] (Klipper's own Welch settings).
//!
//! Several runs of one axis are combined as Klipper's `calibrate_shaper.py` combines them
//! (`calibrate_shaper` → `CalibrationData.add_data` in Klipper's released versions): each run's
//! PSDs linearly interpolated onto the first run's bins and averaged, each run weighted by the
//! number of runs it already holds. Runs that were not normalised are normalised first, as
//! `parse_log` does, when the group mixes both kinds. (Klipper's development branch keeps the
//! runs apart instead and takes the worst shaper response over them; not reproduced here.)

use super::psd::{welch, WelchOptions};
use super::recording::{Channel, Recording, RecordingFormat};
use crate::error::{Error, Result};
use serde::Serialize;

// Klipper's channel, normalisation flag, normalisation and MIN_FREQ: one definition each, in
// `klipper::data` (Klipper's `CalibrationData`), named here as the file reader has used them.
pub use super::klipper::data::{
    normalize as klipper_normalize, Channel as SpectrumChannel, Normalization,
    MIN_FREQ as KLIPPER_MIN_FREQ_HZ,
};

/// A shaper Klipper fitted, as written in a calibration-data file.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FittedShaper {
    /// Klipper's name (`zv`, `mzv`, `ei`, `2hump_ei`, `3hump_ei`, …).
    pub name: String,
    /// Its frequency as written (`%.1f`), Hz.
    pub frequency_hz: f64,
    /// Remaining-vibration ratio at each row's frequency.
    pub values: Vec<f64>,
}

/// A spectrum read from a Klipper file (or computed from a raw recording, or combined).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct SpectrumFile {
    /// `klipperResonances`, `klipperCalibration` (or `klipper` for a raw file's spectrum).
    pub format: RecordingFormat,
    /// The file name given in the options, if any.
    pub file_name: Option<String>,
    /// `x`, `y` or `z`, from the file name (`resonances_x_…`), if it says.
    pub axis: Option<String>,
    /// Bin frequencies, Hz, as in the file.
    pub frequency_hz: Vec<f64>,
    /// `psd_x`.
    pub psd_x: Vec<f64>,
    /// `psd_y`.
    pub psd_y: Vec<f64>,
    /// `psd_z`.
    pub psd_z: Vec<f64>,
    /// `psd_xyz`.
    pub psd_sum: Vec<f64>,
    /// The chosen channel's PSD.
    pub psd: Vec<f64>,
    /// Which channel `psd` is.
    pub channel: SpectrumChannel,
    /// Whether Klipper's normalisation is applied to the PSDs.
    pub normalization: Normalization,
    /// Bin spacing (least-squares slope of the frequencies over the row index; the file rounds
    /// frequencies to 0.1 Hz), Hz.
    pub resolution_hz: f64,
    /// Whether the bins are evenly spaced (within the 0.05 Hz rounding).
    pub even: bool,
    /// The shapers Klipper fitted (calibration-data files).
    pub shapers: Vec<FittedShaper>,
    /// Other columns (e.g. `accel_per_hz`).
    pub extra: Vec<Channel>,
    /// Each run's `psd_xyz` on these bins, when several were combined (or a Klipper file of
    /// several runs, `freq,<run>,<run>,…`, was read: then `psd_sum` is their mean and
    /// `psd_x`, `psd_y`, `psd_z` are empty). Klipper's current `fit_shaper` takes the worst
    /// shaper response over them.
    pub runs: Vec<Channel>,
    /// Runs combined into this spectrum (1 for one file).
    pub sources: usize,
    /// Segment length of the Welch estimate, when known (raw recordings).
    pub segment_length: Option<usize>,
}

impl SpectrumChannel {
    /// The header name of the column.
    pub fn column(self) -> &'static str {
        match self {
            SpectrumChannel::X => "psd_x",
            SpectrumChannel::Y => "psd_y",
            SpectrumChannel::Z => "psd_z",
            SpectrumChannel::Sum => "psd_xyz",
        }
    }
}

impl SpectrumFile {
    /// The PSD of `channel`.
    pub fn channel_psd(&self, channel: SpectrumChannel) -> &[f64] {
        match channel {
            SpectrumChannel::X => &self.psd_x,
            SpectrumChannel::Y => &self.psd_y,
            SpectrumChannel::Z => &self.psd_z,
            SpectrumChannel::Sum => &self.psd_sum,
        }
    }

    /// Chooses the channel `psd` holds.
    pub fn with_channel(mut self, channel: SpectrumChannel) -> Self {
        self.psd = self.channel_psd(channel).to_vec();
        self.channel = channel;
        self
    }

    /// Applies Klipper's normalisation (a no-op when it is applied already).
    pub fn normalized(mut self) -> Self {
        if self.normalization == Normalization::Klipper {
            return self;
        }
        for p in [
            &mut self.psd_x,
            &mut self.psd_y,
            &mut self.psd_z,
            &mut self.psd_sum,
            &mut self.psd,
        ] {
            klipper_normalize(&self.frequency_hz, p);
        }
        self.normalization = Normalization::Klipper;
        self
    }
}

/// The axis a Klipper file name names: the first `_`/`-`/`.`-separated token that is `x`, `y`
/// or `z` (`resonances_x_20240101.csv`, `calibration_data_y_….csv`, `raw_data_x_….csv`).
pub fn axis_from_file_name(name: &str) -> Option<String> {
    let base = name.rsplit(['/', '\\']).next().unwrap_or(name);
    base.split(['_', '-', '.', ' '])
        .map(str::to_ascii_lowercase)
        .find(|t| t == "x" || t == "y" || t == "z")
}

/// Least-squares bin spacing of `f` over the row index, and whether the rows are even to within
/// the 0.05 Hz of `%.1f` rounding (and 0.1 % of a bin).
pub fn resolution_of(f: &[f64]) -> (f64, bool) {
    resolution(f)
}

/// The rows are even when one straight line over the row index passes within the rounding of
/// every row: the narrowest band of parallel lines holding them all (the Chebyshev fit) is at
/// most twice 0.051 Hz (`%.1f`'s half digit) and 0.1 % of a bin wide. The least-squares line's
/// worst residual is no such test: Klipper writes the bins k·f_s/n with `%.1f`, and where
/// f_s/n is a hair under 1.5 Hz (1.4991) the rows step by 1.5 up to 81.0 and by 1.5 again
/// from 82.4 after one step of 1.4, within 0.05 Hz of that grid, but up to 0.061 Hz from the
/// least-squares line through them (real `TEST_RESONANCES` files of a Voron 2.4 were refused
/// so).
pub(crate) fn resolution(f: &[f64]) -> (f64, bool) {
    let n = f.len();
    if n < 2 {
        return (f64::NAN, false);
    }
    let nf = n as f64;
    let mi = 0.5 * (nf - 1.0);
    let mf = f.iter().sum::<f64>() / nf;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, v) in f.iter().enumerate() {
        let d = i as f64 - mi;
        sxy += d * (v - mf);
        sxx += d * d;
    }
    let slope = sxy / sxx;
    let finite = f.iter().all(|v| v.is_finite());
    let even = finite && chebyshev_width(f) <= 2.0 * (0.051 + 1e-3 * slope.abs());
    (slope, even)
}

/// The width of the narrowest band between two parallel lines over the row index that holds
/// every row: min over s of max(fᵢ − s·i) − min(fᵢ − s·i), a convex function of s whose minimum
/// lies between the smallest and largest step (every pair's slope is a mean of steps), found by
/// golden-section search (rows finite).
fn chebyshev_width(f: &[f64]) -> f64 {
    let width = |s: f64| {
        let (lo, hi) =
            f.iter()
                .enumerate()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (i, v)| {
                    let r = v - s * i as f64;
                    (lo.min(r), hi.max(r))
                });
        hi - lo
    };
    let (mut a, mut b) = f
        .windows(2)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), w| {
            let d = w[1] - w[0];
            (lo.min(d), hi.max(d))
        });
    if !(a.is_finite() && b.is_finite()) {
        return f64::NAN;
    }
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut wc, mut wd) = (width(c), width(d));
    for _ in 0..80 {
        if wc <= wd {
            b = d;
            d = c;
            wd = wc;
            c = b - g * (b - a);
            wc = width(c);
        } else {
            a = c;
            c = d;
            wc = wd;
            d = a + g * (b - a);
            wd = width(d);
        }
    }
    wc.min(wd).min(width(0.5 * (a + b)))
}

/// Klipper's spectrum of a raw accelerometer recording (`ShaperCalibrate.calc_freq_response`):
/// Welch with Klipper's settings at f_s = N/T (Klipper's own estimate of the rate, rows over
/// duration) on `accel_x`, `accel_y`, `accel_z` (or the first three channels), not normalised.
pub fn klipper_spectrum(recording: &Recording, channel: SpectrumChannel) -> Result<SpectrumFile> {
    let pick = |name: &str, i: usize| -> Result<&[f64]> {
        recording
            .channel(name)
            .or_else(|| recording.channels.get(i))
            .map(|c| c.values.as_slice())
            .ok_or_else(|| {
                Error::invalid(
                    "recording.channels",
                    "Klipper's spectrum needs three channels (accel_x, accel_y, accel_z)",
                )
            })
    };
    let fs = recording.rows as f64 / recording.duration_s;
    let options = WelchOptions::klipper(fs);
    let m = options.segment_length.unwrap_or(0);
    if recording.rows <= m {
        return Err(Error::invalid(
            "recording",
            format!(
                "{} samples: Klipper's spectrum needs more than one segment of {m}",
                recording.rows
            ),
        ));
    }
    let px = welch(pick("accel_x", 0)?, &options)?;
    let py = welch(pick("accel_y", 1)?, &options)?;
    let pz = welch(pick("accel_z", 2)?, &options)?;
    let sum: Vec<f64> = (0..px.psd.len())
        .map(|k| px.psd[k] + py.psd[k] + pz.psd[k])
        .collect();
    let spectrum = SpectrumFile {
        format: RecordingFormat::Klipper,
        file_name: None,
        axis: None,
        resolution_hz: px.resolution_hz,
        even: true,
        frequency_hz: px.frequency_hz.clone(),
        psd: Vec::new(),
        psd_x: px.psd,
        psd_y: py.psd,
        psd_z: pz.psd,
        psd_sum: sum,
        channel,
        normalization: Normalization::None,
        shapers: Vec::new(),
        extra: Vec::new(),
        runs: Vec::new(),
        sources: 1,
        segment_length: Some(m),
    };
    Ok(spectrum.with_channel(channel))
}

/// Linear interpolation of (x, y) at `at` (clamped to the ends, as `numpy.interp`).
fn interp(x: &[f64], y: &[f64], at: f64) -> f64 {
    let n = x.len();
    if at <= x[0] {
        return y[0];
    }
    if at >= x[n - 1] {
        return y[n - 1];
    }
    let j = x.partition_point(|&v| v <= at).clamp(1, n - 1);
    let (x0, x1) = (x[j - 1], x[j]);
    let t = if x1 > x0 { (at - x0) / (x1 - x0) } else { 0.0 };
    y[j - 1] + t * (y[j] - y[j - 1])
}

/// Combines runs per axis (see the module docs): one spectrum per axis named in the files (in
/// the order first seen; files naming no axis form one group of their own). Errors on an empty
/// list or a spectrum with no bins.
pub fn combine_spectra(files: &[SpectrumFile]) -> Result<Vec<SpectrumFile>> {
    if files.is_empty() {
        return Err(Error::invalid("spectra", "no spectrum to combine"));
    }
    if let Some(i) = files.iter().position(|f| f.frequency_hz.len() < 2) {
        return Err(Error::invalid(
            format!("spectra[{i}]"),
            "has fewer than 2 bins",
        ));
    }
    let mut groups: Vec<(Option<String>, Vec<&SpectrumFile>)> = Vec::new();
    for f in files {
        match groups.iter_mut().find(|(a, _)| *a == f.axis) {
            Some((_, g)) => g.push(f),
            None => groups.push((f.axis.clone(), vec![f])),
        }
    }
    Ok(groups
        .into_iter()
        .map(|(_, group)| {
            let mixed = group
                .iter()
                .any(|f| f.normalization != group[0].normalization);
            let prepared: Vec<SpectrumFile> = group
                .iter()
                .map(|&f| {
                    if mixed {
                        f.clone().normalized()
                    } else {
                        f.clone()
                    }
                })
                .collect();
            let mut out = prepared[0].clone();
            if prepared.len() > 1 {
                out.shapers.clear();
                out.extra.clear();
                out.file_name = None;
                let f = out.frequency_hz.clone();
                out.runs = prepared
                    .iter()
                    .enumerate()
                    .map(|(i, r)| Channel {
                        name: r
                            .file_name
                            .clone()
                            .unwrap_or_else(|| format!("run {}", i + 1)),
                        values: f
                            .iter()
                            .map(|&x| interp(&r.frequency_hz, &r.psd_sum, x))
                            .collect(),
                    })
                    .collect();
            }
            for other in &prepared[1..] {
                let (a, b) = (out.sources as f64, other.sources as f64);
                let f = out.frequency_hz.clone();
                let join = |mine: &mut Vec<f64>, theirs: &[f64]| {
                    for (k, v) in mine.iter_mut().enumerate() {
                        let o = interp(&other.frequency_hz, theirs, f[k]);
                        *v = (*v * a + o * b) / (a + b);
                    }
                };
                if out.psd_x.len() == f.len() && other.psd_x.len() == other.frequency_hz.len() {
                    join(&mut out.psd_x, &other.psd_x);
                    join(&mut out.psd_y, &other.psd_y);
                    join(&mut out.psd_z, &other.psd_z);
                } else {
                    out.psd_x.clear();
                    out.psd_y.clear();
                    out.psd_z.clear();
                }
                join(&mut out.psd_sum, &other.psd_sum);
                out.sources += other.sources;
                out.segment_length = out
                    .segment_length
                    .filter(|_| other.segment_length == out.segment_length);
            }
            let channel = out.channel;
            out.with_channel(channel)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::{chebyshev_width, resolution};

    /// Bins k·Δf written `%.1f`, as Klipper writes them.
    fn written(df: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| format!("{:.1}", k as f64 * df).parse().unwrap())
            .collect()
    }

    /// The narrowest band's width by brute force: the widths over a fine grid of slopes between
    /// the smallest and largest step (an independent computation of the same minimum).
    fn brute_width(f: &[f64]) -> f64 {
        let steps: Vec<f64> = f.windows(2).map(|w| w[1] - w[0]).collect();
        let (a, b) = steps
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
                (lo.min(*d), hi.max(*d))
            });
        (0..=20_000)
            .map(|j| {
                let s = a + (b - a) * j as f64 / 20_000.0;
                let r: Vec<f64> = f
                    .iter()
                    .enumerate()
                    .map(|(i, v)| v - s * i as f64)
                    .collect();
                r.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
                    - r.iter().cloned().fold(f64::INFINITY, f64::min)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Klipper's rows at Δf = 3070.13/2048 = 1.49909 Hz (a real Voron 2.4's `TEST_RESONANCES`
    /// file: steps of 1.5 to 81.0, one of 1.4, then 1.5 again to 199.4) are even, and so are
    /// other spacings written `%.1f`; the least-squares spacing is the grid's.
    #[test]
    fn rows_written_to_a_tenth_of_a_hertz_are_even() {
        let f = written(3070.13 / 2048.0, 134);
        assert_eq!((f[54], f[55], f[133]), (81.0, 82.4, 199.4));
        for (df, n) in [
            (3070.13 / 2048.0, 134),
            (3200.0 / 2048.0, 129),
            (1.4985, 134),
            (0.7812, 257),
        ] {
            let f = written(df, n);
            let (slope, even) = resolution(&f);
            assert!(even, "{df}");
            assert!((slope - df).abs() < 1e-3, "{df}: {slope}");
            let (w, brute) = (chebyshev_width(&f), brute_width(&f));
            assert!(
                w <= brute + 1e-9 && w >= brute - 1e-4,
                "{df}: {w} vs {brute}"
            );
        }
    }

    /// A missing bin, a row 0.2 Hz off, or NaN is not even.
    #[test]
    fn rows_off_the_grid_are_not_even() {
        let f = written(1.5625, 129);
        let mut missing = f.clone();
        missing.remove(60);
        assert!(!resolution(&missing).1);
        let mut off = f.clone();
        off[60] += 0.2;
        assert!(!resolution(&off).1);
        let brute = brute_width(&off);
        assert!((chebyshev_width(&off) - brute).abs() < 1e-4);
        let mut nan = f;
        nan[3] = f64::NAN;
        assert!(!resolution(&nan).1);
    }
}
