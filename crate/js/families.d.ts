// Generated from FAMILIES (crate/design/family.rs) by tests/families.rs: do not edit.
// `UPDATE_DOCS=1 cargo test --test families` rewrites it. docs/js-api.md, *TypeScript*.

/** `zv`: ZV. Guarantees: V = 0 at each mode; shortest positive shaper. Source: Singer & Seering 1988 eq. 6; Singhose 2009 eqs. 14-15. */
export interface ZvSpec {
  family: "zv";
}

/** `zvd`: ZVD. Guarantees: V = 0 and dV/dω = 0 at each mode. Source: Singer & Seering 1988 eq. 7; Singhose 2009 eq. 17. */
export interface ZvdSpec {
  family: "zvd";
}

/** `zvdd`: ZVDD. Guarantees: V = 0 and two derivatives zero at each mode. Source: Singer & Seering 1988 eq. 8. */
export interface ZvddSpec {
  family: "zvdd";
}

/** `zvdn`: ZV-Dⁿ. Guarantees: V = 0 and n derivatives zero at each mode. Source: Singer & Seering 1988 §2.2 (binomial form). */
export interface ZvdnSpec {
  family: "zvdn";
  /** Zero derivatives n. An integer. 0 … 30. Editor default 3. */
  derivatives: number;
}

/** `sampled`: Sampled (t = iT). Guarantees: V = 0 at the mode with `derivatives` derivatives (default 1), impulses at t = iT, ramp delay m·T if asked, amplitude/increment bounds; least control error J_q; one mode. Source: Kamel, Lange & Hirzinger, eqs. 4-25. */
export interface SampledSpec {
  family: "sampled";
  /** Controller period T (s). Editor default 0.012. */
  periodS: number;
  /** Impulses n. An integer. 3 … 256. Editor default 36. */
  impulses: number;
  /** Ramp delay m (periods; blank = free, 0 = full compensation). An integer. Editor default 17. */
  delaySamples?: number | null;
  /** Control-error weight Q. 0 … 1000000. Editor default 0.1. */
  weight?: number;
  /** Zero derivatives. An integer. 0 … 3. Editor default 1. */
  derivatives?: number;
  /** Plant gain K (s²; blank = 1/ω²). */
  plantGain?: number | null;
  /** Objective. Editor default `"controlError"`. */
  objective?: "controlError" | "minimumNorm";
  /** Amplitude min (blank = none). */
  amplitudeMin?: number | null;
  /** Amplitude max (blank = none). */
  amplitudeMax?: number | null;
  /** Increment min (blank = none). */
  incrementMin?: number | null;
  /** Increment max (blank = none). */
  incrementMax?: number | null;
}

/** `ei`: EI. Guarantees: V = vtol with zero slope at each mode, V = 0 either side; exact with damping. Source: Singhose 2009 §3.1, Fig. 7; solved by Newton from the ζ = 0 closed form. */
export interface EiSpec {
  family: "ei";
  /** Hump height V (%). A fraction (0.05 = 5 %). 0.001 … 0.5. Editor default 0.05. */
  vtol?: number;
}

/** `ei2`: Two-hump EI. Guarantees: two humps V = vtol around each mode, V = 0 at the mode and beyond the humps. Source: Singhose 2009 §3.1, Fig. 11; Singhose et al. 1997 (multi-hump). */
export interface Ei2Spec {
  family: "ei2";
  /** Hump height V (%). A fraction (0.05 = 5 %). 0.001 … 0.5. Editor default 0.05. */
  vtol?: number;
}

/** `ei3`: Three-hump EI. Guarantees: three humps V = vtol (the middle one at each mode), four zeros. Source: Singhose 2009 §3.1, Fig. 11; Singhose et al. 1997 (multi-hump). */
export interface Ei3Spec {
  family: "ei3";
  /** Hump height V (%). A fraction (0.05 = 5 %). 0.001 … 0.5. Editor default 0.05. */
  vtol?: number;
}

/** `eihump`: n-hump EI. Guarantees: n humps V = vtol with zero slope, n + 1 zeros around them. Source: Singhose 2009 §3.1; Chebyshev closed form at ζ = 0, Newton with damping. */
export interface EihumpSpec {
  family: "eihump";
  /** Humps n. An integer. 1 … 10. Editor default 2. */
  humps: number;
  /** Hump height V (%). A fraction (0.05 = 5 %). 0.001 … 0.5. Editor default 0.05. */
  vtol?: number;
}

/** `mzv`: MZV (Klipper). Guarantees: V = 0 at each mode; second zero near 5/3 of it; 0.75 damped period. Source: Klipper klippy/extras/shaper_defs.py get_mzv_shaper. */
export interface MzvSpec {
  family: "mzv";
}

/** `umzv`: UM-ZV. Guarantees: V = 0 at each mode; amplitudes +1, -1, +1 (on/off command). Source: Singhose 2009 §5; Singhose, Seering & Singer 1997 (negative shapers). */
export interface UmzvSpec {
  family: "umzv";
}

/** `umzvd`: UM-ZVD. Guarantees: V = 0 and dV/dω = 0 at each mode; amplitudes ±1. Source: Singhose 2009 §5; Singhose, Seering & Singer 1997 (negative shapers). */
export interface UmzvdSpec {
  family: "umzvd";
}

/** `umei`: UM-EI. Guarantees: hump V = vtol at the mode, zeros either side; amplitudes ±1. Source: Singhose 2009 §5; Vaughan, Yano & Singhose 2009. */
export interface UmeiSpec {
  family: "umei";
  /** Hump height V (%). A fraction (0.05 = 5 %). 0.001 … 0.5. Editor default 0.05. */
  vtol?: number;
}

/** `bangbang`: Time-optimal bang-bang. Guarantees: rest-to-rest move of `distance`, V = 0 at the mode; amplitudes sum to 0. Source: Singhose 2009 §5, Fig. 13. */
export interface BangbangSpec {
  family: "bangbang";
  /** Move distance. Editor default 1. */
  distance: number;
  /** Max acceleration (distance/s²). Editor default 10. */
  maxAcceleration: number;
}

/** `onoff`: Fuel-efficient on/off. Guarantees: rest-to-rest move with a coast, no vibration while coasting or after. Source: Singhose 2009 §5, Fig. 14. */
export interface OnoffSpec {
  family: "onoff";
  /** Move distance. Editor default 1. */
  distance: number;
  /** Max acceleration (distance/s²). Editor default 10. */
  maxAcceleration: number;
  /** Coast time (s). Editor default 0.5. */
  coastTime: number;
}

/** `custom`: Custom. Guarantees: none beyond a valid impulse sequence (modes are not used). Source: your own. */
export interface CustomSpec {
  family: "custom";
  /** Impulses: one "time (s), amplitude" per line. */
  impulses: Impulse[];
  /** Normalise amplitudes to sum 1. Editor default `false`. */
  normalize?: boolean;
}

/** `si`: SI (specified insensitivity). Guarantees: V ≤ vtol over the band (whole band, verified densely) or at the sampled frequencies; shortest such shaper. Source: Singhose 2009 eq. 18, Figs. 8-11; Pelaez & Singhose 2002 eqs. 6-7. */
export interface SiSpec {
  family: "si";
  /** Tolerable vibration Vtol (%). A fraction (0.05 = 5 %). Editor default 0.05. */
  vtol?: number;
  /** Insensitivity I (band f(1 ± I/2) around each mode; blank to use the band below). At most 1.98. Editor default 0.4. */
  insensitivity?: number | null;
  /** Band [low, high] Hz (one mode; blank = none). */
  bandHz?: [number, number] | null;
  /** Damping range [ζ low, ζ high] (blank = the modes' ζ). */
  dampingRange?: [number, number] | null;
  /** Sample only these frequencies, Hz (blank = guarantee the whole band). */
  sampleFrequenciesHz?: number[] | null;
  /** Vtol profile: one "frequency Hz, Vtol (fraction)" per line (blank = constant Vtol). */
  vtolProfile?: [number, number][] | null;
  /** Amplitude min (blank = 0). */
  amplitudeMin?: number;
  /** Amplitude max (blank = 1). */
  amplitudeMax?: number;
  /** Max impulses (blank = any). An integer. 1 … 1000. */
  maxImpulses?: number | null;
  /** Max duration (s; blank = none). */
  maxDuration?: number | null;
}

/** `direct`: Direct multi-mode ZV / ZVD. Guarantees: V = 0 and n derivatives zero at every mode at once; shortest such shaper. Source: Singer & Seering 1988 §2.3; Singhose 2009 §4, Fig. 12. */
export interface DirectSpec {
  family: "direct";
  /** Zero derivatives at every mode (0 = ZV, 1 = ZVD …). An integer. 0 … 4. Editor default 1. */
  derivatives?: number;
  /** Amplitude min (blank = 0). */
  amplitudeMin?: number;
  /** Amplitude max (blank = 1). */
  amplitudeMax?: number;
  /** Max duration (s; blank = none). */
  maxDuration?: number | null;
}

/** A shaper family and its parameters, discriminated by `family` (docs/families.md). */
export type ShaperSpec =
  | ZvSpec
  | ZvdSpec
  | ZvddSpec
  | ZvdnSpec
  | SampledSpec
  | EiSpec
  | Ei2Spec
  | Ei3Spec
  | EihumpSpec
  | MzvSpec
  | UmzvSpec
  | UmzvdSpec
  | UmeiSpec
  | BangbangSpec
  | OnoffSpec
  | CustomSpec
  | SiSpec
  | DirectSpec;

/** Every family's name. */
export type FamilyName = ShaperSpec["family"];

/** The families that need the optimisation solver (`solver` not `"never"`). */
export type SolvedFamilyName = "sampled" | "si" | "direct";
