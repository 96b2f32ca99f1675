//! Convergence grid of the solved families (issue 6): SI (with and without a damping range),
//! EI and n-hump EI with damping, direct multi-mode and sampled shapers over ζ ∈ [0, 0.3],
//! insensitivity I ∈ [0.1, 1.5], Vtol ∈ [1 %, 10 %] and 1 … 4 modes with ratios 1.1 … 10.
//!
//! Every point must either return a shaper whose promise an *independent* evaluation confirms —
//! V written out in `tests/independent` from Singhose 2009 eq. 11 (not the library's
//! `vibration` module), scanned densely with every local maximum refined — or a typed error
//! that explains why no such shaper exists. The counts (ok / infeasible with reason / wrong)
//! are printed; no point may be wrong.
//!
//! `cargo test --test convergence` runs the quick grid (part of `npm test`);
//! `cargo test --profile bench --test convergence -- --ignored --nocapture` the full one.
#![cfg(not(target_arch = "wasm32"))]

mod independent;

use independent::{
    check_valid, golden_max, golden_min, max_on_band, pairs, phasor_derivative, v_eq11,
};
use input_shaping::design::direct::DirectSpec;
use input_shaping::design::sampled::{self, SampledSpec};
use input_shaping::design::specified::SiSpec;
use input_shaping::design::{design, zero_vibration};
use input_shaping::{DesignRequest, Error, Mode, ModeSpec, Shaper, ShaperSpec};
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// Relative excess over Vtol that counts as a broken promise (the library checks to 1e-9).
const VTOL_SLACK: f64 = 1e-6;
/// Largest |dᵏP/dωᵏ|/t_nᵏ accepted as zero.
const ZERO_SLACK: f64 = 1e-7;

#[derive(Default)]
struct Tally {
    ok: usize,
    infeasible: usize,
    wrong: Vec<String>,
    /// Error kind and message (first 110 characters) → how often.
    reasons: BTreeMap<String, usize>,
}

struct Grid {
    families: BTreeMap<&'static str, Tally>,
    /// When the previous point was recorded (each point's design + check time is printed).
    last: std::time::Instant,
    /// Which families to run.
    only: Vec<&'static str>,
}

impl Grid {
    /// Records one point: `check` runs on an `Ok` shaper and returns why it is wrong, if it is.
    fn point(
        &mut self,
        family: &'static str,
        what: String,
        result: Result<Shaper, Error>,
        check: impl FnOnce(&Shaper) -> Result<(), String>,
    ) {
        let seconds = self.last.elapsed().as_secs_f64();
        let tally = self.families.entry(family).or_default();
        match result {
            Ok(shaper) => match check_valid(&shaper).and_then(|_| check(&shaper)) {
                Ok(()) => {
                    eprintln!(
                        "  [{seconds:6.2} s] {what}: ok, {} impulses, {:.9} s",
                        shaper.impulses().len(),
                        shaper.duration()
                    );
                    tally.ok += 1
                }
                Err(why) => {
                    eprintln!("  [{seconds:6.2} s] {what}: WRONG {why}");
                    tally.wrong.push(format!("{what}: {why}"))
                }
            },
            Err(e) => {
                eprintln!("  [{seconds:6.2} s] {what}: error: {e}");
                let kind = match &e {
                    Error::Infeasible { .. } => "infeasible",
                    Error::InvalidInput { .. } => "invalid",
                    Error::TooLarge { .. } => "tooLarge",
                    Error::Parse { .. } => "parse",
                    Error::Render { .. } => "render",
                    Error::Unavailable { .. } => "unavailable",
                };
                let text = e.to_string();
                // A parse or render error, or one without a reason, explains nothing.
                if matches!(
                    e,
                    Error::Parse { .. } | Error::Render { .. } | Error::Unavailable { .. }
                ) || text.len() < 20
                {
                    tally.wrong.push(format!("{what}: unexplained error {e:?}"));
                    return;
                }
                tally.infeasible += 1;
                let short: String = text
                    .chars()
                    .map(|c| if c.is_ascii_digit() { '#' } else { c })
                    .take(110)
                    .collect();
                *tally.reasons.entry(format!("{kind}: {short}")).or_default() += 1;
            }
        }
        self.last = std::time::Instant::now();
    }

    fn wants(&self, family: &str) -> bool {
        self.only.contains(&family)
    }

    fn report_and_assert(&self) {
        let (mut ok, mut inf, mut wrong) = (0, 0, 0);
        println!("\nconvergence grid: family: ok / infeasible-with-reason / wrong");
        for (name, t) in &self.families {
            println!(
                "  {name:<12} {:>6} / {:>6} / {:>3}",
                t.ok,
                t.infeasible,
                t.wrong.len()
            );
            for (reason, n) in &t.reasons {
                println!("      {n:>5} × {reason}");
            }
            for w in t.wrong.iter().take(10) {
                println!("      WRONG {w}");
            }
            ok += t.ok;
            inf += t.infeasible;
            wrong += t.wrong.len();
        }
        println!("  {:<12} {ok:>6} / {inf:>6} / {wrong:>3}", "total");
        assert_eq!(
            wrong, 0,
            "{wrong} grid points returned a wrong shaper (listed above)"
        );
    }
}

fn modes_of(freqs: &[f64], zeta: f64) -> Vec<ModeSpec> {
    freqs
        .iter()
        .map(|&f| ModeSpec {
            frequency_hz: f,
            damping: zeta,
        })
        .collect()
}

fn amplitudes_in(imps: &[(f64, f64)], lo: f64, hi: f64) -> Result<(), String> {
    let sum: f64 = imps.iter().map(|p| p.1).sum();
    if (sum - 1.0).abs() > 1e-9 {
        return Err(format!("Σ A = {sum}"));
    }
    for p in imps {
        // The library's bound slack: 1e-8 of the bounds' range (solver tolerance).
        if p.1 < lo - 1e-8 * (hi - lo) || p.1 > hi + 1e-8 * (hi - lo) {
            return Err(format!("amplitude {} outside [{lo}, {hi}]", p.1));
        }
    }
    Ok(())
}

/// Scan points for a band: at least 4000, and ≥ 60 per oscillation of V (V oscillates at the
/// rate t_n in frequency).
fn scan_points(lo: f64, hi: f64, t_n: f64) -> usize {
    (60.0 * (hi - lo) * t_n.max(1e-9))
        .ceil()
        .clamp(4000.0, 400_000.0) as usize
}

/// SI whole-band promise: V ≤ vtol on every band at every damping in `dampings`.
fn check_si(
    shaper: &Shaper,
    bands: &[(f64, f64)],
    dampings: &[f64],
    vtol: f64,
) -> Result<(), String> {
    let imps = pairs(shaper);
    amplitudes_in(&imps, 0.0, 1.0)?;
    let t_n = shaper.duration();
    for &(lo, hi) in bands {
        for &z in dampings {
            let (f, v) = max_on_band(&imps, lo, hi, z, scan_points(lo, hi, t_n));
            if v > vtol * (1.0 + VTOL_SLACK) {
                return Err(format!(
                    "V = {:.6} % > Vtol {:.3} % at {f:.6} Hz, ζ = {z} (band {lo:.4}…{hi:.4})",
                    v * 100.0,
                    vtol * 100.0
                ));
            }
        }
    }
    Ok(())
}

/// Damping levels to check over [lo, hi]: 13 evenly spaced (the library checks 9).
fn damping_levels(lo: f64, hi: f64) -> Vec<f64> {
    if hi <= lo {
        return vec![lo];
    }
    (0..=12).map(|k| lo + (hi - lo) * k as f64 / 12.0).collect()
}

/// n-hump EI promise at one mode, found independently on a dense scan: around the mode, the
/// contiguous region where V ≤ Vtol holds exactly n + 1 zeros (V = 0) and n humps of height
/// Vtol between them; the middle hump (n odd) or the middle zero (n even) is at the mode.
///
/// With damping the region may have no upper edge: at high frequency V tends to the last
/// impulse's amplitude, which can be below Vtol, so V ≤ Vtol from the lower edge on (the full
/// grid's damped 2–4-hump points). Then the promise is checked from the lower edge: the first
/// n + 1 zeros and the n humps below the last of them, interleaved zero, hump, …, zero; above
/// that last zero no further zero (every local minimum above 10⁻³ Vtol) and no further hump
/// (every local maximum below Vtol by 10⁻³ of it) up to the scan's end at 25 f; and beyond the
/// scan, by the triangle inequality on eq. 11, V stays within
/// A_last ∓ Σ_{i<last} |Aᵢ| e^{−ζω(t_n − tᵢ)} (a bound that tightens with ω): below Vtol and
/// above 0, so no zero and no hump hides past the scan either.
fn check_ei(shaper: &Shaper, f_m: f64, zeta: f64, humps: u32, vtol: f64) -> Result<(), String> {
    let imps = pairs(shaper);
    amplitudes_in(&imps, 0.0, 1.0)?;
    let v = |f: f64| v_eq11(&imps, f, zeta);
    // Dense grid over (0, 25 f_m].
    let end = 25.0 * f_m;
    let n = scan_points(0.0, end, shaper.duration()).max(50_000);
    let h = end / n as f64;
    let grid: Vec<f64> = (1..=n).map(|k| v(h * k as f64)).collect();
    let at = |k: usize| h * (k + 1) as f64;
    let centre = ((f_m / h).round() as usize).saturating_sub(1).min(n - 1);
    let limit = vtol * (1.0 + 1e-4);
    if grid[centre] > limit {
        return Err(format!("V = {} at the mode, above Vtol", grid[centre]));
    }
    let (mut left, mut right) = (centre, centre);
    while left > 0 && grid[left - 1] <= limit {
        left -= 1;
    }
    while right + 1 < n && grid[right + 1] <= limit {
        right += 1;
    }
    if left == 0 {
        return Err(format!(
            "the band V ≤ Vtol around the mode reaches 0 Hz ({} … {} Hz)",
            at(left),
            at(right)
        ));
    }
    let open = right + 1 == n;
    // Local minima and maxima of the samples inside [left, right], refined: `zeros` and `tops`
    // the candidates for zeros (below Vtol/2) and humps (above Vtol/2), `extrema` all of them
    // (value, and whether a maximum).
    let (mut zeros, mut tops) = (Vec::new(), Vec::new());
    let mut extrema: Vec<(f64, f64, bool)> = Vec::new();
    let distinct =
        |list: &[(f64, f64)], f: f64| list.last().is_none_or(|&(g, _)| (f - g).abs() > 2.0 * h);
    for k in left.max(1)..=right.min(n - 2) {
        let (a, b) = (at(k) - h, at(k) + h);
        if grid[k] <= grid[k - 1] && grid[k] <= grid[k + 1] {
            let (f, val) = golden_min(v, a, b);
            extrema.push((f, val, false));
            if grid[k] < 0.5 * vtol && distinct(&zeros, f) {
                zeros.push((f, val));
            }
        }
        if grid[k] >= grid[k - 1] && grid[k] >= grid[k + 1] {
            let (f, val) = golden_max(v, a, b);
            extrema.push((f, val, true));
            if grid[k] > 0.5 * vtol && distinct(&tops, f) {
                tops.push((f, val));
            }
        }
    }
    if open {
        // The promise's part of the band: from the lower edge to the (n + 1)-th zero.
        let Some(&(cut, _)) = zeros.get(humps as usize) else {
            return Err(format!(
                "the band V ≤ Vtol from {} Hz reaches the scan's end ({end} Hz) with only {} \
                 zeros (expected {}): {zeros:?}",
                at(left),
                zeros.len(),
                humps + 1
            ));
        };
        for &(f, val, is_max) in extrema.iter().filter(|e| e.0 > cut + 2.0 * h) {
            if is_max && val >= vtol * (1.0 - 1e-3) {
                return Err(format!(
                    "a hump of {val} at {f} Hz above the {}-th zero (n = {humps})",
                    humps + 1
                ));
            }
            if !is_max && val <= 1e-3 * vtol {
                return Err(format!(
                    "an extra zero (V = {val:e}) at {f} Hz above the {}-th zero (n = {humps})",
                    humps + 1
                ));
            }
        }
        zeros.truncate(humps as usize + 1);
        tops.retain(|&(f, _)| f < cut);
        // Interleaved: zero, hump, zero, …, zero.
        if tops.len() == humps as usize {
            for (k, &(f, _)) in tops.iter().enumerate() {
                if !(zeros[k].0 < f && f < zeros[k + 1].0) {
                    return Err(format!(
                        "hump at {f} Hz not between the zeros at {} and {} Hz",
                        zeros[k].0,
                        zeros[k + 1].0
                    ));
                }
            }
        }
        // Beyond the scan: |V − A_last| ≤ Σ_{i<last} |Aᵢ| e^{−ζω(t_n − tᵢ)}, decreasing in ω.
        let w = 2.0 * PI * end;
        let t_n = imps.iter().map(|p| p.0).fold(0.0_f64, f64::max);
        let last: f64 = imps.iter().filter(|p| p.0 == t_n).map(|p| p.1).sum();
        let rest: f64 = imps
            .iter()
            .filter(|p| p.0 < t_n)
            .map(|p| p.1.abs() * (-zeta * w * (t_n - p.0)).exp())
            .sum();
        if last.abs() + rest >= vtol * (1.0 - 1e-3) || last.abs() - rest <= 0.0 {
            return Err(format!(
                "the band V ≤ Vtol reaches the scan's end ({end} Hz) and V beyond it is not \
                 bounded away from Vtol and 0 (last amplitude {last}, rest ≤ {rest:e})"
            ));
        }
    }
    if zeros.len() != humps as usize + 1 || tops.len() != humps as usize {
        return Err(format!(
            "expected {} zeros and {humps} humps around {f_m} Hz, found zeros {zeros:?} humps {tops:?}",
            humps + 1
        ));
    }
    for &(f, val) in &zeros {
        if val > 1e-7 {
            return Err(format!("V = {val:e} at the zero near {f} Hz"));
        }
    }
    for &(f, val) in &tops {
        if (val - vtol).abs() > 1e-7 {
            return Err(format!("hump of {val} at {f} Hz instead of Vtol = {vtol}"));
        }
    }
    let middle = if humps % 2 == 1 {
        tops[humps as usize / 2].0
    } else {
        zeros[humps as usize / 2].0
    };
    if (middle - f_m).abs() > 1e-6 * f_m {
        return Err(format!(
            "middle hump/zero at {middle} Hz, not at the mode {f_m} Hz"
        ));
    }
    Ok(())
}

/// V and its first `derivatives` frequency derivatives vanish at every mode (the complex
/// phasor's derivatives, tests/independent).
fn check_zero_derivatives(
    shaper: &Shaper,
    modes: &[(f64, f64)],
    derivatives: u32,
) -> Result<(), String> {
    let imps = pairs(shaper);
    for &(f, z) in modes {
        for k in 0..=derivatives {
            let d = phasor_derivative(&imps, f, z, k);
            if d > ZERO_SLACK {
                return Err(format!(
                    "|d^{k}P/dω^{k}|/t_n^{k} = {d:e} at {f} Hz, ζ = {z}"
                ));
            }
        }
    }
    Ok(())
}

struct Axes {
    zetas: Vec<f64>,
    insens: Vec<f64>,
    vtols: Vec<f64>,
    /// Mode sets (frequencies in Hz), 1 … 4 modes, ratios 1.1 … 10.
    mode_sets: Vec<Vec<f64>>,
    humps: Vec<u32>,
    direct_derivatives: Vec<u32>,
    /// Sampled: (ωT, impulses).
    sampled: Vec<(f64, usize)>,
    /// Damping range half-widths for SI.
    damping_halfwidths: Vec<f64>,
}

fn run(axes: &Axes, only: &[&'static str]) {
    let mut grid = Grid {
        families: BTreeMap::new(),
        last: std::time::Instant::now(),
        only: only.to_vec(),
    };
    let f0 = 1.0;

    // SI, one mode: ζ × I × Vtol, whole band at the mode's damping.
    if grid.wants("si") {
        for &z in &axes.zetas {
            for &i in &axes.insens {
                for &vtol in &axes.vtols {
                    let spec = SiSpec {
                        vtol,
                        insensitivity: Some(i),
                        ..SiSpec::default()
                    };
                    let what = format!("si f=1 ζ={z} I={i} Vtol={vtol}");
                    let band = [(f0 * (1.0 - i / 2.0), f0 * (1.0 + i / 2.0))];
                    grid.point("si", what, design(&spec.request(modes_of(&[f0], z))), |s| {
                        check_si(s, &band, &[z], vtol)
                    });
                }
            }
        }
    }

    // SI over a damping range [ζ − w, ζ + w] ∩ [0, 0.3].
    if grid.wants("si-damping") {
        for &z in &axes.zetas {
            for &w in &axes.damping_halfwidths {
                for &i in axes.insens.iter().step_by(2) {
                    for &vtol in &axes.vtols {
                        let (lo, hi) = ((z - w).max(0.0), (z + w).min(0.3));
                        let spec = SiSpec {
                            vtol,
                            insensitivity: Some(i),
                            damping_range: Some([lo, hi]),
                            ..SiSpec::default()
                        };
                        let what = format!("si ζ∈[{lo},{hi}] I={i} Vtol={vtol}");
                        let band = [(f0 * (1.0 - i / 2.0), f0 * (1.0 + i / 2.0))];
                        grid.point(
                            "si-damping",
                            what,
                            design(&spec.request(modes_of(&[f0], z))),
                            |s| check_si(s, &band, &damping_levels(lo, hi), vtol),
                        );
                    }
                }
            }
        }
    }

    // SI, several modes: a band of insensitivity I around each.
    if grid.wants("si-modes") {
        for set in axes.mode_sets.iter().filter(|s| s.len() > 1) {
            for &z in axes.zetas.iter().step_by(2) {
                for &i in axes.insens.iter().step_by(2) {
                    let vtol = 0.05;
                    let spec = SiSpec {
                        vtol,
                        insensitivity: Some(i),
                        ..SiSpec::default()
                    };
                    let what = format!("si modes={set:?} ζ={z} I={i}");
                    let bands: Vec<(f64, f64)> = set
                        .iter()
                        .map(|&f| (f * (1.0 - i / 2.0), f * (1.0 + i / 2.0)))
                        .collect();
                    grid.point(
                        "si-modes",
                        what,
                        design(&spec.request(modes_of(set, z))),
                        |s| check_si(s, &bands, &[z], vtol),
                    );
                }
            }
        }
    }

    // EI and n-hump EI with damping, one mode.
    if grid.wants("ei") {
        for &n in &axes.humps {
            for &z in &axes.zetas {
                for &vtol in &axes.vtols {
                    let request = DesignRequest {
                        modes: modes_of(&[f0], z),
                        shaper: ShaperSpec::Eihump { humps: n, vtol },
                    };
                    let what = format!("eihump n={n} ζ={z} Vtol={vtol}");
                    grid.point("ei", what, design(&request), |s| {
                        check_ei(s, f0, z, n, vtol)
                    });
                }
            }
        }
    }

    // EI for several modes (convolved): every factor keeps its promise and the result is their
    // convolution (V is the product of the factors' V).
    if grid.wants("ei-modes") {
        for set in axes.mode_sets.iter().filter(|s| s.len() > 1) {
            for &n in axes.humps.iter().take(2) {
                for &z in axes.zetas.iter().step_by(2) {
                    let vtol = 0.05;
                    let request = DesignRequest {
                        modes: modes_of(set, z),
                        shaper: ShaperSpec::Eihump { humps: n, vtol },
                    };
                    let what = format!("eihump n={n} modes={set:?} ζ={z}");
                    let factors: Vec<Result<Shaper, Error>> = set
                        .iter()
                        .map(|&f| {
                            design(&DesignRequest {
                                modes: modes_of(&[f], z),
                                shaper: ShaperSpec::Eihump { humps: n, vtol },
                            })
                        })
                        .collect();
                    grid.point("ei-modes", what, design(&request), |s| {
                        let imps = pairs(s);
                        let mut fs = Vec::new();
                        for (k, r) in factors.iter().enumerate() {
                            let f = r.as_ref().map_err(|e| format!("factor {k} failed: {e}"))?;
                            check_ei(f, set[k], z, n, vtol)
                                .map_err(|e| format!("factor {k}: {e}"))?;
                            fs.push(pairs(f));
                        }
                        let top = set.iter().fold(0.0_f64, |a, &b| a.max(b)) * 3.0;
                        for j in 1..=3000 {
                            let f = top * j as f64 / 3000.0;
                            let product: f64 = fs.iter().map(|p| v_eq11(p, f, z)).product();
                            let got = v_eq11(&imps, f, z);
                            if (got - product).abs() > 1e-9 * (1.0 + product) {
                                return Err(format!(
                                    "V = {got} at {f} Hz, product of factors {product}"
                                ));
                            }
                        }
                        Ok(())
                    });
                }
            }
        }
    }

    // Direct multi-mode: V and n derivatives zero at every mode; no longer than the convolved
    // ZV-Dⁿ (a feasible point of the same program, so the shortest cannot exceed it).
    if grid.wants("direct") {
        for set in &axes.mode_sets {
            for &z in &axes.zetas {
                for &d in &axes.direct_derivatives {
                    let spec = DirectSpec {
                        derivatives: d,
                        ..DirectSpec::default()
                    };
                    let what = format!("direct n={d} modes={set:?} ζ={z}");
                    let points: Vec<(f64, f64)> = set.iter().map(|&f| (f, z)).collect();
                    let convolved: Option<f64> = set
                        .iter()
                        .map(|&f| Mode::new(f, z).and_then(|m| zero_vibration::zv_dn(&m, d)))
                        .try_fold(Shaper::identity(), |acc, s| acc.convolve(&s?))
                        .ok()
                        .map(|s| s.duration());
                    grid.point(
                        "direct",
                        what,
                        design(&spec.request(modes_of(set, z))),
                        |s| {
                            amplitudes_in(&pairs(s), 0.0, 1.0)?;
                            check_zero_derivatives(s, &points, d)?;
                            if let Some(c) = convolved {
                                if s.duration() > c * 1.01 {
                                    return Err(format!(
                                        "duration {} s longer than the convolved shaper's {c} s",
                                        s.duration()
                                    ));
                                }
                            }
                            Ok(())
                        },
                    );
                }
            }
        }
    }

    // Sampled (Kamel et al.): impulses on t = iT, Σ A = 1, V and derivatives zero at the mode,
    // and the prescribed ramp delay τ = 2ζ/ω + Σ Aᵢtᵢ = mT when asked.
    if grid.wants("sampled") {
        for &z in &axes.zetas {
            for &(wt, n) in &axes.sampled {
                for d in 0..=2u32 {
                    for delay in [None, Some(n as u32 / 2)] {
                        let f = 1.0;
                        let period = wt / (2.0 * PI * f);
                        let spec = SampledSpec {
                            derivatives: d,
                            delay_samples: delay,
                            ..SampledSpec::new(period, n)
                        };
                        let request = DesignRequest {
                            modes: modes_of(&[f], z),
                            shaper: ShaperSpec::Sampled(spec.clone()),
                        };
                        let what = format!("sampled ωT={wt} n={n} d={d} m={delay:?} ζ={z}");
                        let start = Mode::new(f, z)
                            .and_then(|m| sampled::report(&[m], &spec))
                            .map(|r| r.start_time);
                        grid.point("sampled", what, design(&request), |s| {
                            let imps = pairs(s);
                            let sum: f64 = imps.iter().map(|p| p.1).sum();
                            if (sum - 1.0).abs() > 1e-9 {
                                return Err(format!("Σ A = {sum}"));
                            }
                            for p in &imps {
                                let k = p.0 / period;
                                if (k - k.round()).abs() > 1e-6 {
                                    return Err(format!(
                                        "impulse at {} s is not on the period grid",
                                        p.0
                                    ));
                                }
                            }
                            if imps.len() > n {
                                return Err(format!("{} impulses, more than {n}", imps.len()));
                            }
                            check_zero_derivatives(s, &[(f, z)], d)?;
                            if let Some(m) = delay {
                                let t0 =
                                    start.as_ref().map_err(|e| format!("report failed: {e}"))?;
                                let tau = 2.0 * z / (2.0 * PI * f)
                                    + imps.iter().map(|p| p.1 * (p.0 + t0)).sum::<f64>();
                                if (tau - m as f64 * period).abs() > 1e-8 * (1.0 + tau.abs()) {
                                    return Err(format!(
                                        "ramp delay {tau} s instead of {}",
                                        m as f64 * period
                                    ));
                                }
                            }
                            Ok(())
                        });
                    }
                }
            }
        }
    }

    grid.report_and_assert();
}

/// The quick grid (`npm test`): every family and every axis touched, corners included; one
/// test per family group so they run side by side and each reports its own counts.
fn quick_axes() -> Axes {
    Axes {
        zetas: vec![0.0, 0.3],
        insens: vec![0.1, 0.8, 1.5],
        vtols: vec![0.01, 0.1],
        mode_sets: vec![
            vec![1.0],
            vec![1.0, 1.1],
            vec![1.0, 10.0],
            vec![1.0, 2.5, 6.0],
            vec![1.0, 1.1, 3.0, 10.0],
        ],
        humps: vec![1, 2, 3, 4],
        direct_derivatives: vec![0, 1, 2],
        sampled: vec![(0.3, 24), (1.0, 12)],
        damping_halfwidths: vec![0.05],
    }
}

#[test]
fn quick_grid_si() {
    run(&quick_axes(), &["si", "si-damping"]);
}

#[test]
fn quick_grid_si_modes() {
    run(&quick_axes(), &["si-modes"]);
}

#[test]
fn quick_grid_ei() {
    run(&quick_axes(), &["ei", "ei-modes"]);
}

#[test]
fn quick_grid_direct_sampled() {
    run(&quick_axes(), &["direct", "sampled"]);
}

/// The full grid: `cargo test --profile bench --test convergence -- --ignored --nocapture`.
#[test]
#[ignore = "long: the full convergence grid; run with --ignored (see README)"]
fn full_grid() {
    let lin = |a: f64, b: f64, n: usize| -> Vec<f64> {
        (0..n)
            .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
            .collect()
    };
    let round =
        |v: Vec<f64>| -> Vec<f64> { v.into_iter().map(|x| (x * 1e6).round() / 1e6).collect() };
    run(
        &Axes {
            zetas: round(lin(0.0, 0.3, 7)),
            insens: round(lin(0.1, 1.5, 8)),
            vtols: vec![0.01, 0.02, 0.05, 0.1],
            mode_sets: vec![
                vec![1.0],
                vec![1.0, 1.1],
                vec![1.0, 1.5],
                vec![1.0, 3.0],
                vec![1.0, 10.0],
                vec![1.0, 1.1, 1.21],
                vec![1.0, 2.5, 6.0],
                vec![1.0, 3.0, 10.0],
                vec![1.0, 1.1, 3.0, 10.0],
                vec![1.0, 2.0, 4.0, 8.0],
            ],
            humps: vec![1, 2, 3, 4],
            direct_derivatives: vec![0, 1, 2],
            sampled: vec![(0.2, 32), (0.3, 24), (0.6, 16), (1.0, 12), (2.0, 10)],
            damping_halfwidths: vec![0.02, 0.05, 0.1],
        },
        &[
            "si",
            "si-damping",
            "si-modes",
            "ei",
            "ei-modes",
            "direct",
            "sampled",
        ],
    );
}

/// The full grid's damped n-hump EI points whose band V ≤ Vtol runs past the scan's end
/// (humps, ζ, Vtol): V tends to the last impulse's amplitude, below Vtol, at high frequency.
const OPEN_BAND_EI: [(u32, f64, f64); 5] = [
    (2, 0.25, 0.1),
    (3, 0.2, 0.1),
    (3, 0.25, 0.05),
    (4, 0.15, 0.1),
    (4, 0.2, 0.05),
];

fn eihump(humps: u32, zeta: f64, vtol: f64) -> Shaper {
    design(&DesignRequest {
        modes: modes_of(&[1.0], zeta),
        shaper: ShaperSpec::Eihump { humps, vtol },
    })
    .unwrap()
}

/// Those points keep their promise, checked from the band's lower edge (they take that path:
/// V ≤ Vtol at the scan's end).
#[test]
fn ei_open_band_points_keep_their_promise() {
    for (n, z, vtol) in OPEN_BAND_EI {
        let s = eihump(n, z, vtol);
        assert!(
            v_eq11(&pairs(&s), 25.0, z) < vtol,
            "n={n} ζ={z}: band not open"
        );
        check_ei(&s, 1.0, z, n, vtol).unwrap_or_else(|e| panic!("n={n} ζ={z} Vtol={vtol}: {e}"));
    }
}

/// The open-band check still fails wrong shapers: stretched in time (zeros and humps moved off
/// the mode), an amplitude moved (zeros no longer zero), the wrong hump count, a lower Vtol or
/// another damping than the design's.
#[test]
fn ei_open_band_check_catches_wrong_shapers() {
    use input_shaping::Impulse;
    let remake = |s: &Shaper, f: &dyn Fn(usize, &Impulse) -> Impulse| {
        Shaper::new(
            s.impulses()
                .iter()
                .enumerate()
                .map(|(k, i)| f(k, i))
                .collect(),
        )
        .unwrap()
    };
    for (n, z, vtol) in OPEN_BAND_EI {
        let s = eihump(n, z, vtol);
        let stretched = remake(&s, &|_, i| Impulse {
            time: i.time * 1.002,
            amplitude: i.amplitude,
        });
        let moved = remake(&s, &|k, i| Impulse {
            time: i.time,
            amplitude: i.amplitude + [-1e-3, 1e-3].get(k).copied().unwrap_or(0.0),
        });
        let wrong = [
            ("stretched", check_ei(&stretched, 1.0, z, n, vtol)),
            ("amplitude moved", check_ei(&moved, 1.0, z, n, vtol)),
            ("one hump more", check_ei(&s, 1.0, z, n + 1, vtol)),
            ("one hump fewer", check_ei(&s, 1.0, z, n - 1, vtol)),
            ("lower Vtol", check_ei(&s, 1.0, z, n, vtol * 0.99)),
            ("other damping", check_ei(&s, 1.0, z * 0.9, n, vtol)),
        ];
        for (what, result) in wrong {
            assert!(result.is_err(), "n={n} ζ={z} Vtol={vtol}: {what} passed");
        }
    }
}
