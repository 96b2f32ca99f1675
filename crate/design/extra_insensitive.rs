//! Extra-insensitive shapers: EI and n-hump EI, solved exactly with damping.
//!
//! An EI shaper trades the zero of V at the modelling frequency for a tolerable level Vtol:
//! its sensitivity curve V(ω) has n *humps* of height exactly Vtol with zero slope, and n + 1
//! *zeros* around and between them (Singhose 2009 §3.1, Fig. 7; Singhose, Porter, Tuttle &
//! Singer 1997 for the multi-hump shapers). It lasts (n + 1)/2 periods with n + 2 impulses —
//! as long as ZV-Dⁿ, and (Singhose 2009 Fig. 11) the EI shapers lie on the SI curve: the most
//! insensitive shapers of their duration. EI is n = 1 (one hump at the mode, 3 impulses, one
//! period); two-hump EI straddles the mode with two humps and puts a zero on it (4 impulses,
//! 1½ periods); three-hump EI has its middle hump on the mode (5 impulses, 2 periods).
//!
//! ## Undamped closed form (ζ = 0)
//! With the impulses every half period, z = e^{iθ}, θ = πω/ω_m, and the amplitudes symmetric,
//! e^{−imθ/2} Σ Aₖ zᵏ is a real polynomial of degree m = n + 1 in x = cos(θ/2). Equal humps of
//! height Vtol between m zeros, and value 1 at ω = 0 (Σ Aₖ = 1), make it the Chebyshev
//! polynomial
//!
//! g(θ) = ± Vtol · T_m(cos(θ/2) / c),  c = 1 / cosh(arccosh(1/Vtol) / m),
//!
//! so the zeros are at cos(θⱼ/2) = c cos((2j−1)π/2m) and the humps at cos(θ/2) = c cos(kπ/m).
//! The shaper is the product of its zeros, Σ Aₖ zᵏ ∝ Πⱼ (z − e^{iθⱼ}): each conjugate pair is a
//! three-impulse factor [1, −2cos θⱼ, 1] and an odd m adds the ZV factor [1, 1]. This
//! reproduces Singhose's closed forms — EI [(1+V)/4, (1−V)/2, (1+V)/4], two-hump EI with
//! X = (V²(√(1−V²)+1))^{1/3}, three-hump EI with A₁ = (1 + 3V + 2√(2V(V+1)))/16 — which the
//! tests check independently. (The Chebyshev reading is ours; the papers give the closed forms
//! for n ≤ 3 only.)
//!
//! ## With damping
//! The published damped EI shapers are curve fits in ζ. Here they are solved exactly: with
//! the n + 2 amplitudes and the n + 1 times after t₁ = 0 free, and the hump and zero frequencies as
//! further unknowns, the equations are Σ Aᵢ = 1; at each hump V = Vtol and dV/dω = 0 (two
//! each); at each zero P = 0 (two each); the middle hump (n odd) or the middle zero (n even)
//! is pinned at the modelling frequency. That is 4n + 3 equations in 4n + 3 unknowns, solved
//! by Newton's method from the ζ = 0 closed form with continuation in ζ
//! (`design/equations.rs`). The two-hump result agrees with Singhose's published curve fits to
//! their fitting error (see the tests); for one hump the amplitudes agree to 3·10⁻⁴, but the
//! fits keep t₃ = T_d, which the exact solution does not: at ζ = 0.1 its t₂ and t₃ differ from
//! the fits by 2·10⁻³ and 4·10⁻³ T_d.
//!
//! The family ends where its outermost zero runs off to infinite frequency (the design stops
//! following it once that zero passes 20× the mode): at Vtol = 5 % near ζ = 0.68 for EI, 0.44
//! for two humps, 0.28 for three, 0.22 for four; less for larger Vtol, more for smaller.
//! Beyond that no such shaper exists and the design reports it, naming the mode's `damping`.

use super::equations::{continue_in_damping, to_shaper, Equation, Param, System};
use super::Guarantee;
use crate::error::{count, finite, Error, Result};
use crate::mode::Mode;
use crate::shaper::{Impulse, Shaper};
use crate::vibration::vibration_rad;
use nalgebra::DVector;
use std::f64::consts::PI;

/// Most humps accepted (the system has 4n + 3 unknowns).
pub const MAX_HUMPS: u32 = 10;
/// Smallest tolerable vibration accepted: below it zeros and humps crowd together and the
/// equations lose precision (the shaper tends to ZV-Dⁿ).
pub const MIN_VTOL: f64 = 1e-3;
/// Largest tolerable vibration accepted.
pub const MAX_VTOL: f64 = 0.5;
/// Default tolerable vibration (5 %, as in Singhose 2009 §3.1 and Klipper).
pub const DEFAULT_VTOL: f64 = 0.05;

/// An EI design: the shaper and where its humps and zeros are.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtraInsensitive {
    /// The impulse sequence (amplitudes sum to 1, all positive).
    pub shaper: Shaper,
    /// Frequencies of the humps (V = Vtol, dV/dω = 0), Hz, increasing.
    pub humps_hz: Vec<f64>,
    /// Frequencies of the zeros (V = 0), Hz, increasing.
    pub zeros_hz: Vec<f64>,
}

/// EI shaper (one hump at the mode, 3 impulses, about one damped period), Singhose 2009 §3.1.
///
/// ```
/// use input_shaping::{design::extra_insensitive::ei, Mode};
/// // Undamped, Singhose 2009 §3.1: [(1 + V)/4, (1 − V)/2, (1 + V)/4] at [0, T/2, T].
/// let shaper = ei(&Mode::new(1.0, 0.0)?, 0.05)?;
/// let i = shaper.impulses();
/// assert!((i[0].amplitude - 1.05 / 4.0).abs() < 1e-9 && (i[1].amplitude - 0.95 / 2.0).abs() < 1e-9);
/// assert!((i[1].time - 0.5).abs() < 1e-9 && (i[2].time - 1.0).abs() < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn ei(mode: &Mode, vtol: f64) -> Result<Shaper> {
    Ok(extra_insensitive(mode, 1, vtol)?.shaper)
}

/// n-hump EI shaper (`humps` = n, 1 … [`MAX_HUMPS`]): n + 2 impulses over about (n+1)/2
/// damped periods.
///
/// ```
/// use input_shaping::{design::extra_insensitive::ei_humps, vibration::residual_vibration, Mode};
/// let mode = Mode::new(1.0, 0.05)?;
/// let shaper = ei_humps(&mode, 2, 0.05)?; // two humps: 4 impulses over about 1.5 periods
/// assert_eq!(shaper.len(), 4);
/// assert!((shaper.amplitude_sum() - 1.0).abs() < 1e-12);
/// assert!((shaper.duration() / mode.damped_period_s() - 1.5).abs() < 0.05);
/// assert!(residual_vibration(&shaper, &mode) <= 0.05);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn ei_humps(mode: &Mode, humps: u32, vtol: f64) -> Result<Shaper> {
    Ok(extra_insensitive(mode, humps, vtol)?.shaper)
}

/// Checks `vtol` ∈ [[`MIN_VTOL`], [`MAX_VTOL`]] and `humps` ∈ 1 … [`MAX_HUMPS`].
pub(crate) fn check_parameters(humps: u32, vtol: f64) -> Result<()> {
    count("humps", humps as usize, 1, MAX_HUMPS as usize)?;
    finite("vtol", vtol)?;
    if !(MIN_VTOL..=MAX_VTOL).contains(&vtol) {
        return Err(Error::invalid(
            "vtol",
            format!(
                "tolerable vibration must lie between {MIN_VTOL} and {MAX_VTOL} (fraction, \
                 0.05 = 5 %), got {vtol}"
            ),
        ));
    }
    Ok(())
}

/// The undamped n-hump EI (Chebyshev form, module docs), dimensionless: impulses every π
/// (half a period of a mode with ω = 1), and the zeros and humps as ratios ω/ω_m.
pub(crate) struct Undamped {
    /// Amplitudes A₀ … A_{n+1}.
    pub amplitudes: Vec<f64>,
    /// Zeros ω/ω_m, increasing.
    pub zeros: Vec<f64>,
    /// Humps ω/ω_m, increasing.
    pub humps: Vec<f64>,
}

pub(crate) fn undamped(humps: u32, vtol: f64) -> Undamped {
    let m = humps as usize + 1;
    let c = 1.0 / ((1.0 / vtol).acosh() / m as f64).cosh();
    // θ = 2 arccos(x) ∈ (0, 2π) for x = cos(θ/2) ∈ (−1, 1); ω/ω_m = θ/π.
    let ratio = |x: f64| 2.0 * x.acos() / PI;
    let mut zeros: Vec<f64> = (1..=m)
        .map(|j| ratio(c * ((2 * j - 1) as f64 * PI / (2 * m) as f64).cos()))
        .collect();
    let mut hump_list: Vec<f64> = (1..m)
        .map(|k| ratio(c * (k as f64 * PI / m as f64).cos()))
        .collect();
    crate::sort::sort_by(&mut zeros, f64::total_cmp);
    crate::sort::sort_by(&mut hump_list, f64::total_cmp);
    // Multiply out Πⱼ (z² − 2cos θⱼ z + 1) over the zeros below the mode, times (z + 1) if m
    // is odd (the zero at θ = π).
    let mut poly = vec![1.0];
    let mul = |poly: &[f64], factor: &[f64]| {
        let mut out = vec![0.0; poly.len() + factor.len() - 1];
        for (i, p) in poly.iter().enumerate() {
            for (j, f) in factor.iter().enumerate() {
                out[i + j] += p * f;
            }
        }
        out
    };
    for &r in zeros.iter().take(m / 2) {
        poly = mul(&poly, &[1.0, -2.0 * (PI * r).cos(), 1.0]);
    }
    if m % 2 == 1 {
        poly = mul(&poly, &[1.0, 1.0]);
    }
    let sum: f64 = poly.iter().sum();
    Undamped {
        amplitudes: poly.iter().map(|a| a / sum).collect(),
        zeros,
        humps: hump_list,
    }
}

/// Layout of the unknowns: amplitudes, times t₁…t_m, free humps, free zeros.
struct Layout {
    m: usize,
    humps: usize,
    zeros: usize,
    pinned_hump: Option<usize>,
    pinned_zero: Option<usize>,
}

impl Layout {
    fn new(humps: u32) -> Self {
        let n = humps as usize;
        let odd = n % 2 == 1;
        Layout {
            m: n + 1,
            humps: n,
            zeros: n + 1,
            pinned_hump: odd.then_some((n - 1) / 2),
            pinned_zero: (!odd).then_some(n / 2),
        }
    }
    fn unknowns(&self) -> usize {
        4 * self.humps + 3
    }
    /// Parameters of the hump frequencies, in increasing order.
    fn hump_params(&self) -> Vec<Param> {
        let mut next = 2 * self.m + 1;
        (0..self.humps)
            .map(|k| {
                if Some(k) == self.pinned_hump {
                    Param::Fixed(1.0)
                } else {
                    next += 1;
                    Param::Free(next - 1)
                }
            })
            .collect()
    }
    fn zero_params(&self) -> Vec<Param> {
        let free_humps = self.humps - usize::from(self.pinned_hump.is_some());
        let mut next = 2 * self.m + 1 + free_humps;
        (0..self.zeros)
            .map(|k| {
                if Some(k) == self.pinned_zero {
                    Param::Fixed(1.0)
                } else {
                    next += 1;
                    Param::Free(next - 1)
                }
            })
            .collect()
    }
    fn system(&self, zeta: f64, vtol: f64) -> System {
        let mut equations = vec![(Equation::AmplitudeSum(1.0), 0..self.m + 1)];
        for frequency in self.hump_params() {
            equations.push((Equation::Hump { frequency, vtol }, 0..self.m + 1));
        }
        for f in self.zero_params() {
            equations.push((Equation::Zero(f), 0..self.m + 1));
        }
        System {
            zeta,
            amplitudes: (0..=self.m).map(Param::Free).collect(),
            times: std::iter::once(Param::Fixed(0.0))
                .chain((1..=self.m).map(|k| Param::Free(self.m + k)))
                .collect(),
            equations,
            unknowns: self.unknowns(),
        }
    }
}

/// Highest zero accepted, as a multiple of the mode's frequency: beyond it the family has
/// ended (the outer zero escapes to infinity as ζ grows).
const MAX_ZERO_RATIO: f64 = 20.0;

/// Designs the n-hump EI shaper for `mode` (module docs) and verifies it: V = Vtol at each
/// hump and a local maximum there, V = 0 at each zero, V ≤ Vtol between the outer zeros.
///
/// ```
/// use input_shaping::{design::extra_insensitive::extra_insensitive, vibration::residual_vibration, Mode};
/// let mode = Mode::new(5.0, 0.02)?;
/// let ei = extra_insensitive(&mode, 1, 0.05)?;
/// // One hump of V = Vtol at the mode, a zero on either side of it.
/// let (hump, zeros) = (ei.humps_hz[0], &ei.zeros_hz);
/// assert!(zeros[0] < hump && hump < zeros[1]);
/// let at = |f: f64| Mode::new(f, 0.02).map(|m| residual_vibration(&ei.shaper, &m));
/// assert!((at(hump)? - 0.05).abs() < 1e-9);
/// assert!(at(zeros[0])? < 1e-9 && at(zeros[1])? < 1e-9);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn extra_insensitive(mode: &Mode, humps: u32, vtol: f64) -> Result<ExtraInsensitive> {
    check_parameters(humps, vtol)?;
    let start = undamped(humps, vtol);
    let layout = Layout::new(humps);
    let m = layout.m;
    let mut x0 = DVector::zeros(layout.unknowns());
    for (k, a) in start.amplitudes.iter().enumerate() {
        x0[k] = *a;
    }
    for k in 1..=m {
        x0[m + k] = k as f64 * PI;
    }
    for (p, r) in layout.hump_params().into_iter().zip(&start.humps) {
        if let Param::Free(i) = p {
            x0[i] = *r;
        }
    }
    for (p, r) in layout.zero_params().into_iter().zip(&start.zeros) {
        if let Param::Free(i) = p {
            x0[i] = *r;
        }
    }
    let (hp, zp) = (layout.hump_params(), layout.zero_params());
    let valid = |x: &DVector<f64>| {
        let amplitudes_positive = (0..=m).all(|k| x[k] > 0.0);
        let times_increasing = (1..=m).all(|k| x[m + k] > if k == 1 { 0.0 } else { x[m + k - 1] });
        // Zeros and humps interleave: z₀ < h₀ < z₁ < … < h_{n−1} < z_n.
        let mut alternating = Vec::with_capacity(hp.len() + zp.len());
        for (k, z) in zp.iter().enumerate() {
            alternating.push(z.value(x));
            if let Some(h) = hp.get(k) {
                alternating.push(h.value(x));
            }
        }
        let ordered = alternating.windows(2).all(|w| w[0] < w[1])
            && alternating.first().is_some_and(|&f| f > 0.0)
            && alternating.last().is_some_and(|&f| f < MAX_ZERO_RATIO);
        amplitudes_positive && times_increasing && ordered
    };
    let zeta = mode.damping();
    let x = continue_in_damping(zeta, x0, |z| layout.system(z, vtol), valid).map_err(|reached| {
        Error::invalid(
            "damping",
            format!(
                "no {humps}-hump EI shaper with Vtol = {vtol} was found for ζ = {zeta}: the \
                 family, followed from ζ = 0, ends near ζ ≈ {reached:.3} (typically where its \
                 outer zero escapes to infinite frequency); use fewer humps, a smaller vtol, or an SI shaper"
            ),
        )
    })?;
    let system = layout.system(zeta, vtol);
    let impulses: Vec<Impulse> = system.impulses(&x);
    let omega = mode.omega_rad_s();
    let shaper = to_shaper(&impulses, omega)?;
    let f = mode.frequency_hz();
    let design = ExtraInsensitive {
        shaper,
        humps_hz: hp.iter().map(|p| p.value(&x) * f).collect(),
        zeros_hz: zp.iter().map(|p| p.value(&x) * f).collect(),
    };
    verify_extra_insensitive(&design, mode, vtol)?;
    Ok(design)
}

/// Absolute tolerance on V = Vtol at the humps and V = 0 at the zeros.
const TOLERANCE: f64 = 1e-9;

/// Checks the EI promise with [`vibration_rad`], independently of the equations solved.
pub(crate) fn verify_extra_insensitive(
    design: &ExtraInsensitive,
    mode: &Mode,
    vtol: f64,
) -> Result<()> {
    let zeta = mode.damping();
    let v = |f: f64| vibration_rad(design.shaper.impulses(), 2.0 * PI * f, zeta);
    let fail = |what: String| {
        Err(Error::Infeasible {
            reason: format!("the EI design did not verify: {what}"),
        })
    };
    for &f in &design.zeros_hz {
        if v(f).is_nan() || v(f) > TOLERANCE {
            return fail(format!("V = {:.3e} at the zero {f} Hz", v(f)));
        }
    }
    for &f in &design.humps_hz {
        let (here, below, above) = (v(f), v(f * (1.0 - 1e-4)), v(f * (1.0 + 1e-4)));
        if !((here - vtol).abs() <= TOLERANCE && below <= here && above <= here) {
            return fail(format!(
                "V = {here} at the hump {f} Hz, expected a maximum {vtol}"
            ));
        }
    }
    if let (Some(&lo), Some(&hi)) = (design.zeros_hz.first(), design.zeros_hz.last()) {
        let points = 64 * design.zeros_hz.len();
        for i in 0..=points {
            let f = lo + (hi - lo) * i as f64 / points as f64;
            if v(f).is_nan() || v(f) > vtol + TOLERANCE {
                return fail(format!("V = {} > Vtol at {f} Hz", v(f)));
            }
        }
    }
    Ok(())
}

/// (frequency in Hz, damping ratio) points.
type Points = Vec<(f64, f64)>;

/// Zeros (must stay V = 0) and band samples (must stay V ≤ vtol) of a single-mode EI design,
/// for the multi-mode guarantee: convolving positive shapers multiplies V by factors ≤ 1
/// (a positive shaper with Σ Aᵢ = 1 has V ≤ 1 everywhere), so both survive convolution.
fn guarantee_points(design: &ExtraInsensitive, zeta: f64) -> (Points, Points) {
    let zeros = design.zeros_hz.iter().map(|&f| (f, zeta)).collect();
    let band = match (design.zeros_hz.first(), design.zeros_hz.last()) {
        (Some(&lo), Some(&hi)) => (0..=32)
            .map(|i| (lo + (hi - lo) * f64::from(i) / 32.0, zeta))
            .collect(),
        _ => Vec::new(),
    };
    (zeros, band)
}

/// n-hump EI for every mode, convolved, with the guarantee that survives convolution: V = 0
/// at every mode's zeros and V ≤ Vtol between each mode's outer zeros.
pub(crate) fn for_modes(modes: &[Mode], humps: u32, vtol: f64) -> Result<(Shaper, Guarantee)> {
    check_parameters(humps, vtol)?;
    let mut shaper = Shaper::identity();
    let (mut zeros, mut band) = (Vec::new(), Vec::new());
    for (i, mode) in modes.iter().enumerate() {
        let design =
            extra_insensitive(mode, humps, vtol).map_err(|e| e.within(&format!("modes[{i}]")))?;
        let (z, b) = guarantee_points(&design, mode.damping());
        zeros.extend(z);
        band.extend(b);
        shaper = shaper.convolve(&design.shaper)?;
    }
    Ok((
        shaper,
        Guarantee::All(vec![
            Guarantee::ZeroAt(zeros),
            Guarantee::AtMost {
                vtol,
                points: band,
                tolerance: 1e-9,
            },
        ]),
    ))
}
