//! The family table: every family [`design`](super::design) accepts, in one row each, with
//! what the family promises and how each of its parameters is edited (label, kind, limits,
//! default). It is the single source for `families()` in JavaScript (the page builds its
//! parameter editors and its list of solver families from it) and for the family table of
//! `docs/families.md` (generated from it: `tests/families.rs` checks they agree). Klipper keeps
//! one such table too (`klippy/extras/shaper_defs.py`, `INPUT_SHAPERS`).
//!
//! The row and the design are tied together by the family's name: [`ShaperSpec::name`] and the
//! dispatch in [`super`] are exhaustive matches over the spec (the compiler sees a variant
//! without a name or a design), and `tests/families.rs` builds every row's spec from its
//! defaults, parses it, and designs it (a row without a variant, or a variant without a row, fails
//! there). The rows hold no design functions: a pointer to every family's design here would link
//! the optimisation solver into the page's module, which only reads this table.
//!
//! [`ShaperSpec::name`]: super::ShaperSpec::name

use super::{direct, extra_insensitive, sampled, specified, zero_vibration};
use crate::shaper::Impulse;
use serde::Serialize;

/// One row of the family table: what the family is called, what it promises, and its
/// parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FamilyInfo {
    /// The `family` string of a spec.
    pub name: &'static str,
    /// A short human name.
    pub title: &'static str,
    /// What a shaper of this family guarantees.
    pub guarantee: &'static str,
    /// Parameters besides `modes`, as written in a spec (the names of [`FamilyInfo::params`],
    /// in the same order).
    pub parameters: &'static [&'static str],
    /// Where it comes from.
    pub source: &'static str,
    /// How each parameter is edited: label, kind, limits, default.
    pub params: &'static [ParamInfo],
    /// Whether the optimisation solver designs this family (Cargo feature `solver`).
    pub solver: Solver,
}

/// Whether a family needs the optimisation solver (without it, such a design is
/// [`Error::Unavailable`](crate::Error::Unavailable)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "camelCase")]
pub enum Solver {
    /// Never: closed forms and Newton's method.
    Never,
    /// Always.
    Always,
    /// Only when an amplitude or increment bound is given (`sampled`).
    WhenBounded,
}

/// How a parameter's value is written, and so edited.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "camelCase")]
pub enum ParamKind {
    /// A number.
    Number,
    /// A whole number.
    Integer,
    /// A list of numbers (`[low, high]`, frequencies, …).
    Numbers,
    /// A fraction, shown in per cent.
    Percent,
    /// One of [`ParamInfo::options`].
    Select,
    /// True or false.
    Boolean,
    /// Impulses `[{ time, amplitude }]`.
    Pairs,
    /// Points `[[x, y], …]`.
    Points,
}

/// A parameter's starting value in an editor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ParamDefault {
    /// A number.
    Number(f64),
    /// A string (a [`ParamKind::Select`] option).
    Text(&'static str),
    /// True or false.
    Flag(bool),
    /// Impulses.
    Impulses(&'static [Impulse]),
}

/// One parameter of a family: its name in a spec and how it is edited.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct ParamInfo {
    /// The field's name in a spec.
    pub name: &'static str,
    /// What an editor calls it.
    pub label: &'static str,
    /// How its value is written.
    pub kind: ParamKind,
    /// The smallest value accepted (in the spec's units: a fraction for
    /// [`ParamKind::Percent`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// The largest value accepted (in the spec's units).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// The value an editor starts with (none: left out until given).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub default: Option<ParamDefault>,
    /// Whether the spec may leave it out (the design then uses its own default or none).
    pub optional: bool,
    /// The choices of a [`ParamKind::Select`].
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    pub options: &'static [&'static str],
}

impl ParamInfo {
    const fn new(name: &'static str, label: &'static str, kind: ParamKind) -> Self {
        Self {
            name,
            label,
            kind,
            min: None,
            max: None,
            default: None,
            optional: false,
            options: &[],
        }
    }
    const fn number(name: &'static str, label: &'static str) -> Self {
        Self::new(name, label, ParamKind::Number)
    }
    const fn integer(name: &'static str, label: &'static str) -> Self {
        Self::new(name, label, ParamKind::Integer)
    }
    const fn numbers(name: &'static str, label: &'static str) -> Self {
        Self::new(name, label, ParamKind::Numbers)
    }
    const fn percent(name: &'static str, label: &'static str) -> Self {
        Self::new(name, label, ParamKind::Percent)
    }
    const fn range(self, min: f64, max: f64) -> Self {
        Self {
            min: Some(min),
            max: Some(max),
            ..self
        }
    }
    const fn at_most(self, max: f64) -> Self {
        Self {
            max: Some(max),
            ..self
        }
    }
    const fn default(self, value: f64) -> Self {
        Self {
            default: Some(ParamDefault::Number(value)),
            ..self
        }
    }
    const fn optional(self) -> Self {
        Self {
            optional: true,
            ..self
        }
    }
}

/// Hump height of the EI families, 0.1 % … 50 % (5 % by default).
const HUMP_VTOL: ParamInfo = ParamInfo::percent("vtol", "Hump height V (%)")
    .range(extra_insensitive::MIN_VTOL, extra_insensitive::MAX_VTOL)
    .default(extra_insensitive::DEFAULT_VTOL);
const DISTANCE: ParamInfo = ParamInfo::number("distance", "Move distance").default(1.0);
const MAX_ACCELERATION: ParamInfo =
    ParamInfo::number("maxAcceleration", "Max acceleration (distance/s²)").default(10.0);
const MAX_DURATION: ParamInfo =
    ParamInfo::number("maxDuration", "Max duration (s; blank = none)").optional();
/// The solver families' amplitude bounds (the design's defaults: 0 and 1).
const POSITIVE_MIN: ParamInfo =
    ParamInfo::number("amplitudeMin", "Amplitude min (blank = 0)").optional();
const UNIT_MAX: ParamInfo =
    ParamInfo::number("amplitudeMax", "Amplitude max (blank = 1)").optional();

/// Every family [`design`](super::design) accepts.
pub const FAMILIES: &[FamilyInfo] = &[
    FamilyInfo {
        name: "zv",
        title: "ZV",
        guarantee: "V = 0 at each mode; shortest positive shaper",
        parameters: &[],
        source: "Singer & Seering 1988 eq. 6; Singhose 2009 eqs. 14-15",
        params: &[],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "zvd",
        title: "ZVD",
        guarantee: "V = 0 and dV/dω = 0 at each mode",
        parameters: &[],
        source: "Singer & Seering 1988 eq. 7; Singhose 2009 eq. 17",
        params: &[],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "zvdd",
        title: "ZVDD",
        guarantee: "V = 0 and two derivatives zero at each mode",
        parameters: &[],
        source: "Singer & Seering 1988 eq. 8",
        params: &[],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "zvdn",
        title: "ZV-Dⁿ",
        guarantee: "V = 0 and n derivatives zero at each mode",
        parameters: &["derivatives"],
        source: "Singer & Seering 1988 §2.2 (binomial form)",
        params: &[ParamInfo::integer("derivatives", "Zero derivatives n")
            .range(0.0, zero_vibration::MAX_DERIVATIVES as f64)
            .default(3.0)],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "sampled",
        title: "Sampled (t = iT)",
        guarantee: "V = 0 at the mode with `derivatives` derivatives (default 1), impulses at \
                    t = iT, ramp delay m·T if asked, amplitude/increment bounds; least control \
                    error J_q; one mode",
        parameters: &[
            "periodS",
            "impulses",
            "delaySamples",
            "weight",
            "derivatives",
            "plantGain",
            "objective",
            "amplitudeMin",
            "amplitudeMax",
            "incrementMin",
            "incrementMax",
        ],
        source: "Kamel, Lange & Hirzinger, eqs. 4-25",
        params: &[
            ParamInfo::number("periodS", "Controller period T (s)").default(0.012),
            // The fewest a design accepts grows with `derivatives` and `delaySamples`.
            ParamInfo::integer("impulses", "Impulses n")
                .range(sampled::MIN_IMPULSES as f64, sampled::MAX_IMPULSES as f64)
                .default(36.0),
            ParamInfo::integer(
                "delaySamples",
                "Ramp delay m (periods; blank = free, 0 = full compensation)",
            )
            .optional()
            .default(17.0),
            ParamInfo::number("weight", "Control-error weight Q")
                .range(0.0, sampled::MAX_WEIGHT)
                .default(sampled::DEFAULT_WEIGHT),
            ParamInfo::integer("derivatives", "Zero derivatives")
                .range(0.0, sampled::MAX_DERIVATIVES as f64)
                .default(1.0),
            ParamInfo::number("plantGain", "Plant gain K (s²; blank = 1/ω²)").optional(),
            ParamInfo {
                default: Some(ParamDefault::Text("controlError")),
                options: &["controlError", "minimumNorm"],
                ..ParamInfo::new("objective", "Objective", ParamKind::Select)
            },
            ParamInfo::number("amplitudeMin", "Amplitude min (blank = none)").optional(),
            ParamInfo::number("amplitudeMax", "Amplitude max (blank = none)").optional(),
            ParamInfo::number("incrementMin", "Increment min (blank = none)").optional(),
            ParamInfo::number("incrementMax", "Increment max (blank = none)").optional(),
        ],
        solver: Solver::WhenBounded,
    },
    FamilyInfo {
        name: "ei",
        title: "EI",
        guarantee: "V = vtol with zero slope at each mode, V = 0 either side; exact with damping",
        parameters: &["vtol"],
        source: "Singhose 2009 §3.1, Fig. 7; solved by Newton from the ζ = 0 closed form",
        params: &[HUMP_VTOL],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "ei2",
        title: "Two-hump EI",
        guarantee: "two humps V = vtol around each mode, V = 0 at the mode and beyond the humps",
        parameters: &["vtol"],
        source: "Singhose 2009 §3.1, Fig. 11; Singhose et al. 1997 (multi-hump)",
        params: &[HUMP_VTOL],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "ei3",
        title: "Three-hump EI",
        guarantee: "three humps V = vtol (the middle one at each mode), four zeros",
        parameters: &["vtol"],
        source: "Singhose 2009 §3.1, Fig. 11; Singhose et al. 1997 (multi-hump)",
        params: &[HUMP_VTOL],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "eihump",
        title: "n-hump EI",
        guarantee: "n humps V = vtol with zero slope, n + 1 zeros around them",
        parameters: &["humps", "vtol"],
        source: "Singhose 2009 §3.1; Chebyshev closed form at ζ = 0, Newton with damping",
        params: &[
            ParamInfo::integer("humps", "Humps n")
                .range(1.0, extra_insensitive::MAX_HUMPS as f64)
                .default(2.0),
            HUMP_VTOL,
        ],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "mzv",
        title: "MZV (Klipper)",
        guarantee: "V = 0 at each mode; second zero near 5/3 of it; 0.75 damped period",
        parameters: &[],
        source: "Klipper klippy/extras/shaper_defs.py get_mzv_shaper",
        params: &[],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "umzv",
        title: "UM-ZV",
        guarantee: "V = 0 at each mode; amplitudes +1, -1, +1 (on/off command)",
        parameters: &[],
        source: "Singhose 2009 §5; Singhose, Seering & Singer 1997 (negative shapers)",
        params: &[],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "umzvd",
        title: "UM-ZVD",
        guarantee: "V = 0 and dV/dω = 0 at each mode; amplitudes ±1",
        parameters: &[],
        source: "Singhose 2009 §5; Singhose, Seering & Singer 1997 (negative shapers)",
        params: &[],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "umei",
        title: "UM-EI",
        guarantee: "hump V = vtol at the mode, zeros either side; amplitudes ±1",
        parameters: &["vtol"],
        source: "Singhose 2009 §5; Vaughan, Yano & Singhose 2009",
        params: &[HUMP_VTOL],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "bangbang",
        title: "Time-optimal bang-bang",
        guarantee: "rest-to-rest move of `distance`, V = 0 at the mode; amplitudes sum to 0",
        parameters: &["distance", "maxAcceleration"],
        source: "Singhose 2009 §5, Fig. 13",
        params: &[DISTANCE, MAX_ACCELERATION],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "onoff",
        title: "Fuel-efficient on/off",
        guarantee: "rest-to-rest move with a coast, no vibration while coasting or after",
        parameters: &["distance", "maxAcceleration", "coastTime"],
        source: "Singhose 2009 §5, Fig. 14",
        params: &[
            DISTANCE,
            MAX_ACCELERATION,
            ParamInfo::number("coastTime", "Coast time (s)").default(0.5),
        ],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "custom",
        title: "Custom",
        guarantee: "none beyond a valid impulse sequence (modes are not used)",
        parameters: &["impulses", "normalize"],
        source: "your own",
        params: &[
            ParamInfo {
                default: Some(ParamDefault::Impulses(&[
                    Impulse {
                        time: 0.0,
                        amplitude: 0.5,
                    },
                    Impulse {
                        time: 0.25,
                        amplitude: 0.5,
                    },
                ])),
                ..ParamInfo::new(
                    "impulses",
                    "Impulses: one \"time (s), amplitude\" per line",
                    ParamKind::Pairs,
                )
            },
            ParamInfo {
                default: Some(ParamDefault::Flag(false)),
                ..ParamInfo::new(
                    "normalize",
                    "Normalise amplitudes to sum 1",
                    ParamKind::Boolean,
                )
            },
        ],
        solver: Solver::Never,
    },
    FamilyInfo {
        name: "si",
        title: "SI (specified insensitivity)",
        guarantee: "V ≤ vtol over the band (whole band, verified densely) or at the sampled \
                    frequencies; shortest such shaper",
        parameters: &[
            "vtol",
            "insensitivity",
            "bandHz",
            "dampingRange",
            "sampleFrequenciesHz",
            "vtolProfile",
            "amplitudeMin",
            "amplitudeMax",
            "maxImpulses",
            "maxDuration",
        ],
        source: "Singhose 2009 eq. 18, Figs. 8-11; Pelaez & Singhose 2002 eqs. 6-7",
        params: &[
            ParamInfo::percent("vtol", "Tolerable vibration Vtol (%)").default(0.05),
            ParamInfo::number(
                "insensitivity",
                "Insensitivity I (band f(1 ± I/2) around each mode; blank to use the band below)",
            )
            .at_most(specified::MAX_INSENSITIVITY)
            .optional()
            .default(0.4),
            ParamInfo::numbers("bandHz", "Band [low, high] Hz (one mode; blank = none)").optional(),
            ParamInfo::numbers(
                "dampingRange",
                "Damping range [ζ low, ζ high] (blank = the modes' ζ)",
            )
            .optional(),
            ParamInfo::numbers(
                "sampleFrequenciesHz",
                "Sample only these frequencies, Hz (blank = guarantee the whole band)",
            )
            .optional(),
            ParamInfo::new(
                "vtolProfile",
                "Vtol profile: one \"frequency Hz, Vtol (fraction)\" per line (blank = constant \
                 Vtol)",
                ParamKind::Points,
            )
            .optional(),
            POSITIVE_MIN,
            UNIT_MAX,
            ParamInfo::integer("maxImpulses", "Max impulses (blank = any)")
                .range(1.0, specified::MAX_IMPULSES_PARAMETER as f64)
                .optional(),
            MAX_DURATION,
        ],
        solver: Solver::Always,
    },
    FamilyInfo {
        name: "direct",
        title: "Direct multi-mode ZV / ZVD",
        guarantee: "V = 0 and n derivatives zero at every mode at once; shortest such shaper",
        parameters: &["derivatives", "amplitudeMin", "amplitudeMax", "maxDuration"],
        source: "Singer & Seering 1988 §2.3; Singhose 2009 §4, Fig. 12",
        params: &[
            ParamInfo::integer(
                "derivatives",
                "Zero derivatives at every mode (0 = ZV, 1 = ZVD …)",
            )
            .range(0.0, direct::MAX_DIRECT_DERIVATIVES as f64)
            .default(1.0),
            POSITIVE_MIN,
            UNIT_MAX,
            MAX_DURATION,
        ],
        solver: Solver::Always,
    },
];
