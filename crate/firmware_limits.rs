//! What each firmware's input shaper accepts, read from the firmware's own source (GPL: read
//! and cited, never copied). One home for the numbers: the optimiser ([`crate::measure::optimal`],
//! which keeps its custom shapers within them) and the config writer
//! ([`crate::export::firmware`], which checks every shaper against them as written) both read
//! them from here.

use serde::Serialize;

/// Kalico's largest custom shaper: `struct shaper_pulses` holds `pulses[25]` and `init_shaper`
/// refuses more (KalicoCrew/kalico, klippy/chelper/kin_shaper.c, `init_shaper`, at commit
/// 197f6ff). dmbutyugin/klipper's branch holds 5 (klippy/chelper/kin_shaper.h).
pub const KALICO_MAX_IMPULSES: usize = 25;
/// Kalico rejects a custom amplitude of magnitude below this ("All shaper A coefficients must
/// be non-zero", klippy/extras/input_shaper.py, `CustomInputShaperParams._parse_custom_shaper`).
pub const KALICO_MIN_ABS_AMPLITUDE: f64 = 0.001;
/// Kalico rejects custom amplitudes summing below this (`_parse_custom_shaper`).
pub const KALICO_MIN_AMPLITUDE_SUM: f64 = 0.001;
/// Kalico rejects a custom shaper of several impulses shorter than this, s
/// (`_parse_custom_shaper`).
pub const KALICO_MIN_DURATION_S: f64 = 0.001;
/// Kalico rejects a custom shaper longer than this, s ("Shaper duration is too large",
/// `_parse_custom_shaper`).
pub const KALICO_MAX_DURATION_S: f64 = 0.2;
/// RepRapFirmware holds at most 5 impulses: RRF 3.6 src/Movement/AxisShaper.h `MaxImpulses = 5`
/// (rechrtb/RepRapFirmware 204471f), earlier AxisShaper.h `MaxExtraImpulses = 4` besides the
/// first (Duet3D/RepRapFirmware); `AxisShaper::Configure` reads `H` and `T` as at most 4 values
/// each.
pub const RRF_MAX_IMPULSES: usize = 5;
/// Lowest `M593 F` accepted by every RRF 3.6 source read: AxisShaper.cpp limits F to
/// [StepClockRate/(2·65535), 1000] Hz (half period in a 16-bit count of 750 kHz step clocks),
/// the 3.6 header (rechrtb/RepRapFirmware 204471f, AxisShaper.h) to [4, 400] Hz.
pub const RRF_MIN_FREQUENCY_HZ: f64 = 750_000.0 / (2.0 * 65535.0);
/// Highest `M593 F` accepted by every RRF 3.6 source read (see [`RRF_MIN_FREQUENCY_HZ`]).
pub const RRF_MAX_FREQUENCY_HZ: f64 = 400.0;
/// RRF limits `M593 S` to [0, 0.99] (`GetLimitedFValue('S', 0.0, 0.99)`).
pub const RRF_MAX_DAMPING: f64 = 0.99;

/// What a firmware's custom shaper accepts (positive amplitudes normalised to Σ A = 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FirmwareLimits {
    /// Most impulses.
    pub max_impulses: usize,
    /// Longest shaper (last impulse time), s.
    pub max_duration_s: f64,
    /// Shortest shaper with more than one impulse, s.
    pub min_duration_s: f64,
    /// Smallest amplitude (after normalising to Σ A = 1).
    pub min_amplitude: f64,
}

/// Kalico's `shaper_type_<axis>: custom` (the `KALICO_*` constants). Kalico also takes negative
/// amplitudes; these limits are for positive ones.
pub const KALICO_CUSTOM: FirmwareLimits = FirmwareLimits {
    max_impulses: KALICO_MAX_IMPULSES,
    max_duration_s: KALICO_MAX_DURATION_S,
    min_duration_s: KALICO_MIN_DURATION_S,
    min_amplitude: KALICO_MIN_ABS_AMPLITUDE,
};

/// RepRapFirmware's `M593 P"custom"`: [`RRF_MAX_IMPULSES`], positive amplitudes (refused
/// otherwise by [`crate::export::to_rrf_m593`]). RRF states no duration bound nor smallest
/// amplitude; Kalico's are used for it too.
pub const RRF_CUSTOM: FirmwareLimits = FirmwareLimits {
    max_impulses: RRF_MAX_IMPULSES,
    max_duration_s: KALICO_MAX_DURATION_S,
    min_duration_s: KALICO_MIN_DURATION_S,
    min_amplitude: KALICO_MIN_ABS_AMPLITUDE,
};
