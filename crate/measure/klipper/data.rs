//! Klipper's calibration data: PSD bins of one or several runs, and its frequency
//! normalisation.
//!
//! Read from Klipper3d/klipper `klippy/extras/shaper_calibrate.py` (commit
//! 034cb6734a9a2b0c56e3ccee6c33866526c8cbab, class `CalibrationData`: `add_data`,
//! `normalize_to_frequencies`, `get_datasets`) and `scripts/calibrate_shaper.py` (`parse_log`,
//! `calibrate_shaper`); the code here is our own.
//!
//! - **Several runs** are kept side by side, not averaged: `add_data` appends the other run's
//!   data sets, and the fit pessimises over them (the largest remaining vibration of any run;
//!   the curves' maximum on a common 0.2 Hz grid). Older Klipper (before 2024) averaged the
//!   runs, interpolated onto the first run's bins (`join`); that is not reproduced.
//! - **Normalisation** (`normalize_to_frequencies`), applied once per run: every PSD is divided
//!   by f + 0.1 (Hz), and below 2·`MIN_FREQ` = 10 Hz further multiplied by
//!   e^{1 − (10/(f + 0.1))²}, which removes low-frequency noise smoothly (older Klipper zeroed
//!   the bins below 5 Hz instead). `calibrate_shaper.py` normalises raw recordings and
//!   `resonances_*.csv` files; a file that carries fitted shapers (`,shapers:` in its header,
//!   written by `SHAPER_CALIBRATE`) is already normalised.
//! - **Channel**: Klipper fits `psd_sum` (x + y + z; the `psd_xyz` column). [`Channel`] lets
//!   a caller fit one axis instead; [`Channel::Sum`] is Klipper's choice.

use crate::error::{count, Error, Result};
use serde::{Deserialize, Serialize};

/// Klipper's `MIN_FREQ`, Hz: the normalisation damps the bins below twice this.
pub const MIN_FREQ: f64 = 5.0;
/// Most bins per run accepted.
pub const MAX_BINS: usize = 1 << 21;
/// Most runs combined.
pub const MAX_DATASETS: usize = 64;

/// Which PSD the fit reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Channel {
    /// x + y + z (`psd_xyz`), Klipper's.
    #[default]
    Sum,
    /// The x axis.
    X,
    /// The y axis.
    Y,
    /// The z axis.
    Z,
}

/// Whether Klipper's normalisation is applied to a spectrum (JS `"none"` | `"klipper"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Normalization {
    /// The PSD as Welch computed it (raw recordings, `resonances_*.csv`).
    #[default]
    None,
    /// Klipper's `normalize_to_frequencies` applied (`calibration_data_*.csv`).
    Klipper,
}

/// One run: bins and PSDs (Klipper's `CalibrationData` of one data set).
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    /// A name (file name or column), for messages.
    pub name: String,
    /// Bin frequencies, Hz, non-decreasing.
    pub freq_bins: Vec<f64>,
    /// x + y + z.
    pub psd_sum: Vec<f64>,
    /// x, y, z (absent in multi-run calibration files, which store the sum only).
    pub psd_xyz: Option<[Vec<f64>; 3]>,
    /// Whether Klipper's normalisation has been applied.
    pub normalized: bool,
}

impl Dataset {
    /// A run from bins and the summed PSD, checked: 1 … [`MAX_BINS`] bins, finite
    /// non-decreasing frequencies ≥ 0, finite PSD values ≥ 0, equal lengths. `normalized` says
    /// whether Klipper's normalisation is already applied.
    pub fn new(
        name: impl Into<String>,
        freq_bins: Vec<f64>,
        psd_sum: Vec<f64>,
        psd_xyz: Option<[Vec<f64>; 3]>,
        normalized: bool,
    ) -> Result<Self> {
        count("frequencyHz", freq_bins.len(), 1, MAX_BINS)?;
        let mut prev = 0.0;
        for (i, &f) in freq_bins.iter().enumerate() {
            if !(f.is_finite() && f >= prev) {
                return Err(Error::invalid(
                    format!("frequencyHz[{i}]"),
                    format!("must be finite, ≥ 0 and not below the bin before, got {f}"),
                ));
            }
            prev = f;
        }
        check_psd("psd", &psd_sum, freq_bins.len())?;
        if let Some(xyz) = &psd_xyz {
            for (p, field) in xyz.iter().zip(["psdX", "psdY", "psdZ"]) {
                check_psd(field, p, freq_bins.len())?;
            }
        }
        Ok(Dataset {
            name: name.into(),
            freq_bins,
            psd_sum,
            psd_xyz,
            normalized,
        })
    }

    /// The PSD of `channel`; `None` when the run stores the sum only.
    pub fn psd(&self, channel: Channel) -> Option<&[f64]> {
        match channel {
            Channel::Sum => Some(&self.psd_sum),
            Channel::X => self.psd_xyz.as_ref().map(|p| p[0].as_slice()),
            Channel::Y => self.psd_xyz.as_ref().map(|p| p[1].as_slice()),
            Channel::Z => self.psd_xyz.as_ref().map(|p| p[2].as_slice()),
        }
    }

    /// Applies Klipper's normalisation to every PSD of the run, once (see the module docs).
    pub fn normalize_to_frequencies(&mut self) {
        if self.normalized {
            return;
        }
        let freq = &self.freq_bins;
        normalize(freq, &mut self.psd_sum);
        if let Some(xyz) = &mut self.psd_xyz {
            for p in xyz.iter_mut() {
                normalize(freq, p);
            }
        }
        self.normalized = true;
    }
}

/// Checks one PSD column: `n` finite values ≥ 0.
fn check_psd(field: &str, psd: &[f64], n: usize) -> Result<()> {
    if psd.len() != n {
        return Err(Error::invalid(
            field,
            format!("has {} values but frequencyHz has {n}", psd.len()),
        ));
    }
    for (i, &p) in psd.iter().enumerate() {
        if !(p.is_finite() && p >= 0.0) {
            return Err(Error::invalid(
                format!("{field}[{i}]"),
                format!("must be a finite value ≥ 0, got {p}"),
            ));
        }
    }
    Ok(())
}

/// Klipper's `normalize_to_frequencies` on one PSD: P /= f + 0.1, then below 2·MIN_FREQ
/// P *= e^{1 − (2·MIN_FREQ/(f + 0.1))²} (the same operations in the same order).
pub fn normalize(freq_bins: &[f64], psd: &mut [f64]) {
    for (p, &f) in psd.iter_mut().zip(freq_bins) {
        *p /= f + 0.1;
        if f < 2.0 * MIN_FREQ {
            let r = 2.0 * MIN_FREQ / (f + 0.1);
            *p *= (-(r * r) + 1.0).exp();
        }
    }
}

/// Klipper's calibration data: one or several runs of one axis (`CalibrationData` with its
/// `data_sets`).
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationData {
    datasets: Vec<Dataset>,
}

impl CalibrationData {
    /// Data of one run.
    pub fn new(first: Dataset) -> Self {
        CalibrationData {
            datasets: vec![first],
        }
    }

    /// Adds another run (Klipper's `add_data`: kept as a separate data set). Error: more than
    /// [`MAX_DATASETS`] runs.
    pub fn add_data(&mut self, other: CalibrationData) -> Result<()> {
        count(
            "datasets",
            self.datasets.len() + other.datasets.len(),
            1,
            MAX_DATASETS,
        )?;
        self.datasets.extend(other.datasets);
        Ok(())
    }

    /// Every run, the first first (Klipper's `get_datasets`).
    pub fn datasets(&self) -> &[Dataset] {
        &self.datasets
    }

    /// Normalises every run not yet normalised (Klipper's `normalize_to_frequencies`).
    pub fn normalize_to_frequencies(&mut self) {
        for d in &mut self.datasets {
            d.normalize_to_frequencies();
        }
    }
}
