//! # input-shaping
//!
//! Design and analysis of input shapers. A flexible machine driven by a reference command rings
//! at its modes; convolving the command with a short sequence of impulses whose vibrations
//! cancel at those modes (an *input shaper*) removes the residual vibration, and robust shapers
//! keep doing so when the model is wrong (Singer & Seering 1988; Singhose 2009).
//!
//! ```
//! use input_shaping::{design::zero_vibration::zvd, vibration::residual_vibration, Mode};
//! let mode = Mode::new(2.0, 0.05)?;              // 2 Hz, ζ = 0.05
//! let shaper = zvd(&mode)?;                        // three impulses over one damped period
//! assert!(residual_vibration(&shaper, &mode) < 1e-12);
//! # Ok::<(), input_shaping::Error>(())
//! ```
//!
//! ## Module map
//! - [`mode`]: a validated vibration mode (frequency in Hz, damping ratio).
//! - [`shaper`]: the impulse sequence, convolution, duration, centroid delay.
//! - [`vibration`]: V(ω, ζ) (Singhose 2009 eq. 11), sensitivity curves over frequency and
//!   damping, the frequency × damping map, insensitivity bands.
//! - [`design`](mod@design): the spec, the table of families, and one file per family of the literature.
//! - [`smoothing`]: Klipper-compatible smoothing and suggested maximum acceleration.
//! - [`export`]: CSV, JSON, C arrays and RepRapFirmware `M593` lines.
//! - [`realise`](mod@realise): what a controller runs instead of the designed shaper (Klipper,
//!   Kalico, RRF, Marlin classic and FT_MOTION, Prusa, a generic period/steps/cap), and what it
//!   costs.
//! - [`firmware_limits`]: what each firmware's shaper accepts (impulses, duration, amplitudes,
//!   frequency), cited from its source; read by the optimiser and the config writer.
//! - [`command`]: reference commands (step, ramp, trapezoid, S-curve, sampled) and shaping
//!   them (exact convolution, streaming filter).
//! - [`profile`]: pulse-convolution profiles and their B-spline form (Veciana & Cardona 2011).
//! - [`plant`]: modal LTI, two-mass spring, nonlinear pendulum; [`simulate`]: their responses;
//!   [`metrics`]: residual vibration, settling, delay, peaks; [`spectrum`]: |U(f)|.
//! - [`robustness`]: robustness against duration across families (Singhose 2009 Fig. 11).
//! - [`solve`]: the shortest shaper under vibration constraints (convex program on a time grid,
//!   bisection on the duration, Newton polish, dense checks) shared by the solved families.
//! - [`chart`]: charts drawn with plotters on any backend (canvas in the page, SVG in tests).
//! - [`error`]: the one error type; nothing reachable from the public API panics.
//! - [`measure`]: measured data — recordings, FFT and Welch PSD, mode identification with
//!   uncertainties, shaper recommendation over the measured spectrum.
//! - [`scenario`]: a whole spec run at once (design, shaped command, simulation, metrics;
//!   spectra).
//! - [`piecewise`]: piecewise polynomials in jump form, the shape of every analytic command.
//! - `js` (wasm32 only): everything for JavaScript — the JavaScript API (`design`,
//!   `residualVibration`, `sensitivity`, …), its measured-data part (`parseRecording`, `welch`,
//!   `identifyModes`, …), the reader of JS values and the canvas backend.
//!
//! ## Layers
//!
//! Each line may import only from the lines above it, and modules on one line may import each
//! other only one way (no circles). `tests/layers.rs` reads this list and fails `npm test` when
//! an import points up or two modules import each other; a new top-level module must be
//! listed here.
//!
//! ```text
//! ground     error mode shaper sort tagged firmware_limits
//! analysis   vibration smoothing
//! numerics   solve
//! design     design
//! motion     piecewise profile command
//! plants     plant
//! results    simulate metrics spectrum robustness corner
//! scenario   scenario
//! measured   measure
//! charts     chart
//! export     export realise
//! js         js
//! ```
//!
//! `robustness` (durations and insensitivities across families) designs every family, so it
//! sits above design, with the other results, not with the single-shaper analysis.

pub mod chart;
pub mod command;
pub mod corner;
pub mod design;
pub mod error;
pub mod export;
pub mod firmware_limits;
pub mod measure;
pub mod metrics;
pub mod mode;
pub mod piecewise;
pub mod plant;
pub mod profile;
pub mod realise;
pub mod robustness;
pub mod scenario;
pub mod shaper;
pub mod simulate;
pub mod smoothing;
pub mod solve;
mod sort;
pub mod spectrum;
mod tagged;
pub mod vibration;

#[cfg(target_arch = "wasm32")]
pub mod js;

pub use design::{design, DesignRequest, ShaperSpec};
pub use error::{Error, Result};
pub use mode::{Mode, ModeSpec};
pub use shaper::{Impulse, Shaper};
