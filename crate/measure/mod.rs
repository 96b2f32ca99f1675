//! Measured data: from a recording to the modes and a recommended shaper.
//!
//! - [`recording`]: CSV (Klipper's raw accelerometer files as they are, or any CSV with a time
//!   column), uneven time stamps resampled, read in chunks.
//! - [`fft`]: the discrete Fourier transform (radix-2 and Bluestein, any length).
//! - [`psd`]: Welch's power spectral density and the plain FFT amplitude spectrum.
//! - [`identify`](mod@identify) (split by stage: `peaks`, `half_power`, `spectrum_fit`, `decay`): peaks → frequency and damping ratio by half-power bandwidth, a fit of the
//!   modal spectrum, and a least-squares fit of the free decay, each with an uncertainty.
//! - [`klipper`]: Klipper's own recommendation reproduced (its shaper table, normalisation,
//!   frequency scan and selection rules).
//! - [`recommend`]: the shaper families scored over the measured spectrum (Klipper's
//!   remaining-vibration, smoothing and max-accel definitions) against their duration.

pub mod fft;
mod fit;
pub mod identify;
pub mod klipper;
pub mod optimal;
pub mod psd;
pub mod recommend;
pub mod recording;
pub mod spectrum_file;

pub use identify::{
    identify, CutOff, Identification, IdentifiedMode, IdentifyOptions, SignalKind, Sweep, SweepLaw,
};
pub use psd::{fft_spectrum, welch, FftOptions, Psd, WelchOptions, WindowKind};
pub use recording::{parse_recording, Recording, RecordingOptions, RecordingParser};
