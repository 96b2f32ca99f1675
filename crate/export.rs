//! Exports of a shaper in the forms people paste into tools and controllers: CSV, JSON, a C
//! array, and a RepRapFirmware `M593` line; [`firmware`]: per-axis configs for Klipper, Kalico,
//! RepRapFirmware and Marlin.

pub mod firmware;

use crate::error::{Error, Result};
use crate::shaper::Shaper;
use std::fmt::Write;

/// `time_s,amplitude` with a header and one row per impulse, numbers in Rust's shortest
/// round-trip form (reading them back gives the same f64).
pub fn to_csv(shaper: &Shaper) -> String {
    let mut out = String::from("time_s,amplitude\n");
    for imp in shaper.impulses() {
        let _ = writeln!(out, "{},{}", imp.time, imp.amplitude);
    }
    out
}

/// The same object `design` returns: `{"impulses":[{"time":…,"amplitude":…}],"duration":…}`,
/// numbers in shortest round-trip form.
pub fn to_json(shaper: &Shaper) -> String {
    let mut out = String::from("{\"impulses\":[");
    for (i, imp) in shaper.impulses().iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        let _ = write!(
            out,
            "{{\"time\":{},\"amplitude\":{}}}",
            imp.time, imp.amplitude
        );
    }
    let _ = write!(out, "],\"duration\":{}}}", shaper.duration());
    out
}

/// Checks a C identifier.
fn c_identifier(name: &str) -> Result<&str> {
    let mut chars = name.chars();
    let first_ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    if first_ok && name.len() <= 64 && chars.all(|c| c.is_ascii_alphanumeric() || c == '_') {
        Ok(name)
    } else {
        Err(Error::invalid(
            "name",
            format!("must be a C identifier (letters, digits, _; not starting with a digit; at most 64 characters), got {name:?}"),
        ))
    }
}

/// A comment safe to put inside `/* … */` on one line.
fn c_comment(text: &str) -> String {
    text.replace("*/", "* /")
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .take(200)
        .collect()
}

/// A C float literal with 9 significant digits (enough to round-trip a `float`).
fn c_float(x: f64) -> String {
    let s = format!("{:.8e}", x);
    // Rust writes 1.23456789e-3; C accepts the same form with an `f` suffix.
    format!("{s}f")
}

/// A C header fragment with the impulse times (s) and amplitudes as `float` arrays named
/// `<name>_time_s` and `<name>_amplitude`, their length as `<NAME>_COUNT`, and `comment` on
/// the first line.
pub fn to_c_float(shaper: &Shaper, name: &str, comment: &str) -> Result<String> {
    let name = c_identifier(name)?;
    let upper = name.to_ascii_uppercase();
    let n = shaper.len();
    let join = |f: &dyn Fn(&crate::shaper::Impulse) -> f64| {
        shaper
            .impulses()
            .iter()
            .map(|imp| c_float(f(imp)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut out = String::new();
    let _ = writeln!(out, "/* {} */", c_comment(comment));
    let _ = writeln!(
        out,
        "/* {n} impulses, duration {} s, amplitudes sum to {} */",
        shaper.duration(),
        shaper.amplitude_sum()
    );
    let _ = writeln!(out, "#define {upper}_COUNT {n}");
    let _ = writeln!(
        out,
        "static const float {name}_time_s[{upper}_COUNT] = {{ {} }};",
        join(&|imp| imp.time)
    );
    let _ = writeln!(
        out,
        "static const float {name}_amplitude[{upper}_COUNT] = {{ {} }};",
        join(&|imp| imp.amplitude)
    );
    Ok(out)
}

/// A C header fragment for integer controllers: amplitudes as integer counts of
/// 1/`amplitude_steps` (`int32_t <name>_amplitude_q[]`, summing exactly to `amplitude_steps` for
/// a unity-gain shaper) and times as integer counts of `tick_s` (`uint32_t <name>_time_ticks[]`),
/// rounded by [`crate::design::quantize::quantize`] (largest remainder; impulses landing on the
/// same tick are merged). Peláez & Singhose 2002 show what such rounding costs in robustness;
/// `quantize` reports it.
pub fn to_c_fixed(
    shaper: &Shaper,
    name: &str,
    comment: &str,
    amplitude_steps: u32,
    tick_s: f64,
) -> Result<String> {
    use crate::design::quantize::{quantize, QuantizeOptions};
    let name = c_identifier(name)?;
    let upper = name.to_ascii_uppercase();
    let rounded = quantize(
        shaper,
        &QuantizeOptions {
            tick_s: Some(tick_s),
            ..QuantizeOptions::new(amplitude_steps)
        },
    )?;
    let steps = f64::from(amplitude_steps);
    let q: Vec<String> = rounded
        .impulses()
        .iter()
        .map(|imp| format!("{}", (imp.amplitude * steps).round() as i64))
        .collect();
    if rounded.duration() / tick_s > f64::from(u32::MAX) {
        return Err(Error::invalid(
            "tickS",
            format!("{tick_s} s is too fine: the tick counts do not fit in 32 bits"),
        ));
    }
    let ticks: Vec<String> = rounded
        .impulses()
        .iter()
        .map(|imp| format!("{}", (imp.time / tick_s).round() as u64))
        .collect();
    let mut out = String::new();
    let _ = writeln!(out, "/* {} */", c_comment(comment));
    let _ = writeln!(
        out,
        "/* fixed point: amplitude = q / {amplitude_steps}, time = ticks * {tick_s} s; {} impulses */",
        rounded.len()
    );
    let _ = writeln!(out, "#define {upper}_COUNT {}", rounded.len());
    let _ = writeln!(out, "#define {upper}_AMPLITUDE_SCALE {amplitude_steps}");
    let _ = writeln!(
        out,
        "static const int32_t {name}_amplitude_q[{upper}_COUNT] = {{ {} }};",
        q.join(", ")
    );
    let _ = writeln!(
        out,
        "static const uint32_t {name}_time_ticks[{upper}_COUNT] = {{ {} }};",
        ticks.join(", ")
    );
    Ok(out)
}

/// A number with up to 7 significant digits and no exponent, trailing zeros trimmed (RRF's
/// G-code parser reads plain decimals).
fn gcode_number(x: f64) -> String {
    let digits = if x == 0.0 {
        0
    } else {
        (6 - x.abs().log10().floor() as i32).clamp(0, 12) as usize
    };
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A RepRapFirmware `M593 P"custom"` line, with the semantics of **RRF 3.6.0 and later**:
/// `H` lists the amplitudes of every impulse except the last (RRF sets the last to 1 minus
/// their sum, so they must sum to less than 1) and `T` the cumulative delays in seconds of every
/// impulse except the first (strictly increasing). RRF 3.5 and earlier read `H` and `T`
/// differently (T as durations between impulses); this line is not for them.
///
/// Errors unless the shaper has at least two and at most
/// [`firmware::RRF_MAX_IMPULSES`] impulses (RRF 3.6 AxisShaper.h `MaxImpulses`: `H` and `T`
/// take at most 4 values), positive amplitudes summing to 1 (within 1e-9) — which is what RRF
/// can represent. (RRF's `M593` code does not check the sign; negative amplitudes are refused
/// here because its motion planner was not read for them.)
pub fn to_rrf_m593(shaper: &Shaper) -> Result<String> {
    let imps = shaper.impulses();
    if imps.len() < 2 {
        return Err(Error::invalid(
            "impulses",
            "RRF's custom shaper needs at least two impulses",
        ));
    }
    if imps.len() > firmware::RRF_MAX_IMPULSES {
        return Err(Error::invalid(
            "impulses",
            format!(
                "RepRapFirmware holds at most {} impulses (AxisShaper.h MaxImpulses), this \
                 shaper has {}",
                firmware::RRF_MAX_IMPULSES,
                imps.len()
            ),
        ));
    }
    if (shaper.amplitude_sum() - 1.0).abs() > 1e-9 {
        return Err(Error::invalid(
            "impulses",
            format!(
                "RRF's custom shaper needs amplitudes summing to 1, got {}",
                shaper.amplitude_sum()
            ),
        ));
    }
    if let Some(i) = imps.iter().position(|imp| imp.amplitude <= 0.0) {
        return Err(Error::invalid(
            format!("impulses[{i}].amplitude"),
            "RRF's custom shaper takes positive amplitudes only",
        ));
    }
    let h: Vec<String> = imps[..imps.len() - 1]
        .iter()
        .map(|imp| gcode_number(imp.amplitude))
        .collect();
    let t: Vec<String> = imps[1..].iter().map(|imp| gcode_number(imp.time)).collect();
    Ok(format!(
        "M593 P\"custom\" H{} T{}",
        h.join(":"),
        t.join(":")
    ))
}
