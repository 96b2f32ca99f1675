//! Klipper's shaper recommendation, reproduced: its shaper table ([`shapers`]), its calibration
//! data and frequency normalisation ([`data`]), and its fit (`fit_shaper`, `find_best_shaper`,
//! and Klipper's figures of any shaper: [`fit`]).
//!
//! Read from Klipper3d/klipper (`klippy/extras/shaper_defs.py` at commit
//! 1819369886bac3e5210674c0e9b36ae60619ce82, `klippy/extras/shaper_calibrate.py` at commit
//! 034cb6734a9a2b0c56e3ccee6c33866526c8cbab, `scripts/calibrate_shaper.py` of the same
//! generation: several runs kept apart, the smooth low-frequency normalisation,
//! `MAX_SHAPER_FREQ` = 200 Hz, the damped EI fits). The code is our own (Klipper is GPL).

pub mod data;
pub mod fit;
pub mod shapers;

pub use data::{CalibrationData, Channel, Dataset};
pub use fit::{
    find_best_shaper, fit_shaper, klipper_figures_on, FamilyFit, FitOptions, FitPoint, KlipperFit,
    Printed, ShaperFigures, ShaperFreqs,
};
pub use shapers::{klipper_shaper, shaper_def, KlipperShaperDef, KLIPPER_SHAPERS};
