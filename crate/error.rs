//! The one error type of the library.
//!
//! Every public function validates its input at the edge and returns [`Error`] instead of
//! panicking. The message names the offending field the way a user wrote it
//! (`modes[0].damping`), so the page can show it next to that field.

use std::fmt;

/// What went wrong, with the field it concerns.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A value is out of its domain (NaN, infinite, negative frequency, damping ≥ 1, …).
    InvalidInput {
        /// The field, as the user names it (`modes[0].frequencyHz`, `points`).
        field: String,
        /// Why it is rejected, with the value.
        reason: String,
    },
    /// A request is too large to compute with bounded memory and time.
    TooLarge {
        /// The field whose size is excessive.
        field: String,
        /// The value given.
        value: f64,
        /// The largest value accepted.
        limit: f64,
    },
    /// The request is valid but no shaper satisfies it (e.g. an SI band too wide).
    Infeasible {
        /// Why, in words.
        reason: String,
    },
    /// A spec could not be parsed (unknown family, wrong type, missing field).
    Parse {
        /// Path to the offending field, e.g. `modes[0].frequencyHz` (empty if unknown).
        field: String,
        /// The parser's message.
        reason: String,
    },
    /// A chart could not be drawn (the drawing backend failed).
    Render {
        /// The backend's message.
        reason: String,
    },
    /// The request needs a part of the library this build leaves out: the optimisation solver
    /// of the solved families (`si`, `direct`, and `sampled` when an amplitude or increment
    /// bound is active), Cargo feature `solver`. Only builds without that feature return it:
    /// the page's first wasm module, which fetches the module with the solver when it sees
    /// this error (docs/page-performance.md, *Shipped size*).
    Unavailable {
        /// The field whose value needs the left-out part (`shapers[0]`, say).
        field: String,
        /// What is left out and why it is needed.
        reason: String,
    },
}

impl Error {
    /// Shorthand for [`Error::InvalidInput`].
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::InvalidInput {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// The [`Error::Unavailable`] of a solved family's design in a build without the solver.
    #[cfg_attr(feature = "solver", allow(dead_code))]
    pub(crate) fn solver_left_out() -> Self {
        Error::Unavailable {
            field: String::new(),
            reason: "this shaper is designed by the optimisation solver, which this build of \
                     the library leaves out (Cargo feature `solver`)"
                .into(),
        }
    }

    /// The field this error concerns, if any.
    pub fn field(&self) -> Option<&str> {
        match self {
            Error::InvalidInput { field, .. }
            | Error::TooLarge { field, .. }
            | Error::Parse { field, .. }
            | Error::Unavailable { field, .. } => Some(field.as_str()).filter(|f| !f.is_empty()),
            Error::Infeasible { .. } | Error::Render { .. } => None,
        }
    }

    /// Prefixes the field with `prefix.` (used when validating nested objects).
    pub fn within(self, prefix: &str) -> Self {
        let join = |f: String| {
            if f.is_empty() {
                prefix.to_string()
            } else if f.starts_with('[') {
                format!("{prefix}{f}")
            } else {
                format!("{prefix}.{f}")
            }
        };
        match self {
            Error::InvalidInput { field, reason } => Error::InvalidInput {
                field: join(field),
                reason,
            },
            Error::TooLarge {
                field,
                value,
                limit,
            } => Error::TooLarge {
                field: join(field),
                value,
                limit,
            },
            Error::Parse { field, reason } => Error::Parse {
                field: join(field),
                reason,
            },
            Error::Unavailable { field, reason } => Error::Unavailable {
                field: join(field),
                reason,
            },
            e @ (Error::Infeasible { .. } | Error::Render { .. }) => e,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidInput { field, reason } => write!(f, "{field}: {reason}"),
            Error::TooLarge {
                field,
                value,
                limit,
            } => write!(
                f,
                "{field}: {value} is too large (at most {limit} to keep memory and time bounded)"
            ),
            Error::Infeasible { reason } => write!(f, "infeasible: {reason}"),
            Error::Render { reason } => write!(f, "chart could not be drawn: {reason}"),
            Error::Parse { field, reason } | Error::Unavailable { field, reason } => {
                if field.is_empty() {
                    write!(f, "{reason}")
                } else {
                    write!(f, "{field}: {reason}")
                }
            }
        }
    }
}

impl std::error::Error for Error {}

/// Result alias used across the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Checks that `value` is finite, naming `field` otherwise.
pub(crate) fn finite(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be a finite number, got {value}"),
        ))
    }
}

/// Checks that `value` is finite and strictly positive.
pub(crate) fn positive(field: &str, value: f64) -> Result<f64> {
    finite(field, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be greater than 0, got {value}"),
        ))
    }
}

/// Checks that a count lies in `1..=limit`.
pub(crate) fn count(field: &str, value: usize, min: usize, limit: usize) -> Result<usize> {
    if value < min {
        Err(Error::invalid(
            field,
            format!("must be at least {min}, got {value}"),
        ))
    } else if value > limit {
        Err(Error::TooLarge {
            field: field.to_string(),
            value: value as f64,
            limit: limit as f64,
        })
    } else {
        Ok(value)
    }
}
