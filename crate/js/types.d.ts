// The TypeScript types of the JavaScript API's arguments and results (docs/js-api.md), appended
// to the `.d.ts` that wasm-bindgen generates for every module (crate/js/mod.rs); the exports'
// signatures name them (`unchecked_param_type` / `unchecked_return_type` in crate/js/*.rs).
// The family specs (`ShaperSpec`, `FamilyName`) are generated from the family table:
// crate/js/families.d.ts. `npm test` compiles an example and a file of mistakes against them,
// and checks that every export's real result is of its declared type (tests/types/).

// ---------------------------------------------------------------------------------------------
// Errors

/** What went wrong: `invalid` input, a `tooLarge` request, an `infeasible` design, a `parse`
 * error (a wrong type, a missing field, a bad recording line), a `render` failure, or
 * `unavailable` (a solved family in a module built without the solver). */
export type ErrorKind = "invalid" | "tooLarge" | "infeasible" | "parse" | "render" | "unavailable";

/** Every export throws this (a JS `Error`) on bad input, never a wasm trap. `message` starts
 * with the field. */
export interface InputShapingError extends Error {
  kind: ErrorKind;
  /** The offending field, named from the argument (`modes[0].damping`, `options.points`). */
  field?: string;
  /** Recording errors (`parseRecording`, `RecordingParser`): the 1-based line. */
  line?: number;
  /** Recording errors: the 1-based column, when one is at fault. */
  column?: number;
  /** Recording errors: that column's name. */
  columnName?: string;
  /** Recording errors: the `fileName` option. */
  file?: string;
}

// ---------------------------------------------------------------------------------------------
// Shapers and modes

/** One impulse: time in seconds, amplitude (a fraction of the command). */
export interface Impulse {
  time: number;
  amplitude: number;
}

/** A vibration mode: frequency in Hz (1e-9 … 1e9), damping ratio 0 ≤ ζ < 1 (default 0). */
export interface ModeSpec {
  frequencyHz: number;
  damping?: number;
}

/** A shaper as `design` returns it: impulses sorted by time, the first at 0. */
export interface Shaper {
  impulses: Impulse[];
  /** Time of the last impulse, s. */
  duration: number;
  /** Only for a convolution of more than 4096 impulses (up to 65 536), kept factored: its
   * factors' impulses (one shaper's each), whose convolution `impulses` is. V of the shaper is
   * the product of the factors' V. Ignored when the shaper is passed back. */
  factors?: Impulse[][];
  /** Only from `design` of a family the optimisation solver designs (`si`, `direct`): how it
   * was reached. Ignored when the shaper is passed back. */
  solver?: SolverReport;
}

/** How the optimisation solver reached an `si` or `direct` design (`design(spec).solver`). */
export interface SolverReport {
  /** The Newton polish converged: the shaper is exact and locally optimal. `false`: it is the
   * grid solution — it meets every constraint, but it may be up to a grid step longer than
   * the optimum and has the grid's impulses (often many). */
  polished: boolean;
  /** Rounds of the exchange loop (1 when the first design met every band). */
  rounds: number;
  /** Convex programs solved. */
  programs: number;
}

/** A shaper as the functions take it: `duration` is optional and ignored. */
export interface ShaperInput {
  impulses: Impulse[];
  duration?: number;
}

/** `design(spec)`: a family, its parameters, and the modes to design for. */
export type DesignSpec = ShaperSpec & {
  /** At least one mode, none repeated. */
  modes: ModeSpec[];
};

/** A family spec with its own modes, optional (`simulate`'s and `spectrum`'s `shaper`:
 * the plant's modes unless given). */
export type ShaperRequest = ShaperSpec & {
  modes?: ModeSpec[] | null;
};

// ---------------------------------------------------------------------------------------------
// Analysis

export interface SensitivityOptions {
  fromHz: number;
  toHz: number;
  /** 2 … 100 000. */
  points: number;
  damping?: number;
}

export interface SensitivityCurve {
  frequencyHz: number[];
  vibration: number[];
}

/** I(Vtol): the band around the mode where V ≤ vtol; `width` as a fraction of the frequency. */
export interface Insensitivity {
  lowHz: number;
  highHz: number;
  width: number;
}

export interface SensitivityMapOptions {
  fromHz: number;
  toHz: number;
  frequencyPoints: number;
  dampingFrom: number;
  dampingTo: number;
  dampingPoints: number;
}

export interface SensitivityMap {
  frequencyHz: number[];
  damping: number[];
  /** Row-major, one row per damping value. */
  vibration: Float64Array;
}

export interface DampingSensitivityOptions {
  frequencyHz: number;
  fromDamping: number;
  toDamping: number;
  points: number;
}

export interface DampingSensitivityCurve {
  damping: number[];
  vibration: number[];
}

export interface DampingInsensitivity {
  lowDamping: number;
  highDamping: number;
  width: number;
}

/** One row of `robustnessTable` (Singhose 2009 Fig. 11). */
export interface RobustnessRow {
  spec: ShaperSpec;
  title: string;
  /** Number of impulses. */
  impulses: number;
  durationS: number;
  durationPeriods: number;
  insensitivity: number;
  dampingInsensitivity: number;
}

/** One parameter of a family, as the page's editors show it. */
export interface ParamInfo {
  name: string;
  label: string;
  kind: "number" | "integer" | "numbers" | "percent" | "select" | "boolean" | "pairs" | "points";
  min?: number;
  max?: number;
  default?: number | string | boolean | Impulse[];
  optional: boolean;
  options?: string[];
}

/** One row of the family table (`families()`). */
export interface FamilyInfo {
  name: FamilyName;
  title: string;
  guarantee: string;
  parameters: string[];
  source: string;
  params: ParamInfo[];
  solver: "never" | "always" | "whenBounded";
}

export interface ExportOptions {
  format: "csv" | "json" | "c" | "cFixed" | "rrf";
  name?: string | null;
  comment?: string | null;
  amplitudeSteps?: number | null;
  tickS?: number | null;
}

/** Klipper's figures: smoothing in mm, the suggested max acceleration in mm/s² (`null`:
 * unbounded, a single impulse). */
export interface KlipperFigures {
  smoothing: number;
  maxAccel: number | null;
}

export interface KlipperFiguresOptions {
  /** Square corner velocity, mm/s (default 5). */
  scv?: number;
}

export interface Cost {
  total: number;
  controlError: number;
  amplitudePenalty: number;
}

export interface SampledReport extends Shaper {
  startTime: number;
  rampDelay: number;
  cost: Cost;
  baselineCost: Cost;
  costReduction: number;
}

/** `design`'s spec of the family `sampled` (`sampledReport`). */
export type SampledDesignSpec = SampledSpec & { modes: ModeSpec[] };

export interface QuantizeOptions {
  /** Amplitude resolution N, 1 … 2²⁴. */
  amplitudeSteps: number;
  tickS?: number | null;
  method?: "largestRemainder" | "updateTime";
  rampS?: number | null;
  vtol?: number;
}

export interface QuantizeReport extends Shaper {
  amplitudeSum: number;
  vtol: number;
  vibrationBefore: number;
  vibrationAfter: number;
  insensitivityBefore: Insensitivity;
  insensitivityAfter: Insensitivity;
}

/** The controller of `realizeShaper` (docs/js-api.md, *What your controller runs*). */
export type Controller =
  | "ideal"
  | "klipper"
  | "kalico"
  | "rrf"
  | "marlin"
  | "marlinFtMotion"
  | "prusa"
  | "generic";

export interface RealizeOptions {
  firmware: Controller;
  /** s: Marlin's timer tick, FT_MOTION's period, the generic controller's period. */
  periodS?: number | null;
  /** Generic controller: amplitudes to multiples of 1/N, 1 … 2²⁴. */
  amplitudeSteps?: number | null;
  /** Generic controller: most impulses, 1 … 10000. */
  maxImpulses?: number | null;
  vtol?: number;
  /** V(f) of both shapers over this range, at the first mode's damping. */
  curve?: { fromHz: number; toHz: number; points: number } | null;
}

export interface RealizationChange {
  kind: "family" | "times" | "amplitudes" | "impulses" | "modes";
  text: string;
}

export interface RealizationMode {
  frequencyHz: number;
  damping: number;
  vibrationIdeal: number;
  vibrationRealised: number;
}

export interface Realization {
  firmware: Controller;
  ideal: Shaper;
  realised: Shaper;
  /** The family the controller runs, in its own form, or "custom". */
  runs: string;
  changes: RealizationChange[];
  summary: string;
  modes: RealizationMode[];
  vtol: number;
  insensitivityIdeal: Insensitivity;
  insensitivityRealised: Insensitivity;
  /** The frequency the realised shaper acts at when its times are the ideal ones scaled. */
  actsAsHz: number | null;
  sensitivityIdeal: SensitivityCurve | null;
  sensitivityRealised: SensitivityCurve | null;
}

/** `drawRealisation`'s data: each shaper's V(f) designed and realised (the page's view). */
export interface RealisationChartData {
  shapers: { label: string; color?: string; ideal: SensitivityCurve; realised: SensitivityCurve }[];
  vtol?: number | null;
  modesHz?: number[];
}

// ---------------------------------------------------------------------------------------------
// Commands, plants, simulation

export interface StepCommand {
  kind: "step";
  distance?: number;
  start?: number;
}
export interface RampCommand {
  kind: "ramp";
  slope?: number;
  start?: number;
}
export interface TrapezoidCommand {
  kind: "trapezoid";
  distance: number;
  maxVelocity: number;
  maxAcceleration: number;
  start?: number;
}
export interface SCurveCommand {
  kind: "sCurve";
  distance: number;
  maxVelocity: number;
  maxAcceleration: number;
  maxJerk: number;
  start?: number;
}
export interface SampledCommand {
  kind: "sampled";
  samplePeriod: number;
  values: number[];
  interpolation?: "linear" | "hold";
}
/** Pulse-convolution profiles (Veciana & Cardona 2011), discriminated by `shape`. */
export type ProfileSpec =
  | { shape: "pulse"; frequencyHz: number; distance: number; duration: number }
  | { shape: "triangle"; frequencyHz: number; distance: number; duration: number }
  | { shape: "robustTrapezium"; frequencyHz: number; deltaHz: number; distance: number; duration: number }
  | { shape: "multiMode"; modesHz: number[]; commonHz?: number | null; distance: number; duration: number };
export type ProfileCommand = { kind: "profile" } & ProfileSpec;
/** A reference command, discriminated by `kind`. */
export type CommandSpec =
  | StepCommand
  | RampCommand
  | TrapezoidCommand
  | SCurveCommand
  | SampledCommand
  | ProfileCommand;

export interface PlantModeSpec {
  frequencyHz: number;
  damping?: number;
  participation?: number | null;
}
/** A plant, discriminated by `kind`. */
export type PlantSpec =
  | { kind: "modal"; modes: PlantModeSpec[] }
  | { kind: "twoMass"; baseMass: number; tipMass: number; stiffness: number; dampingCoefficient?: number }
  | {
      kind: "pendulum";
      length: number;
      gravity?: number;
      damping?: number;
      initialAngle?: number;
      hoist?: CommandSpec | null;
    }
  | { kind: "vecianaTestBed" };

export interface SimulationSpec {
  plant: PlantSpec;
  command: CommandSpec;
  shaper?: ShaperRequest | null;
  impulses?: Impulse[] | null;
  duration?: number | null;
  samplePeriod?: number | null;
  sampleRateHz?: number | null;
}

/** `null` where a metric does not apply. */
export interface Metrics {
  moveEnd: number;
  distance: number | null;
  residualVibrationPercent: number | null;
  residualAmplitude: number | null;
  /** Modal plants only. */
  modeResidualPercent?: number[];
  settlingTime2: number | null;
  settlingTime5: number | null;
  riseTime: number | null;
  delay: number | null;
  peakDeflection: number;
  peakAcceleration: number | null;
  peakJerk: number | null;
  accelerationPeakValleyCount: number;
}

export interface Response {
  basePosition: number[];
  baseVelocity: number[];
  baseAcceleration: number[];
  endpoint: number[];
  endpointVelocity: number[];
  endpointAcceleration: number[];
  deflection: number[];
  /** Pendulum only. */
  swingAngle?: number[];
  metrics: Metrics;
}

export interface SimulationResult {
  time: number[];
  unshaped: Response;
  shaped: Response | null;
  shaper: Shaper | null;
  modesHz: number[];
  samplePeriod: number;
}

export interface SpectrumSpec {
  command: CommandSpec;
  shaper?: ShaperRequest | null;
  impulses?: Impulse[] | null;
  plant?: PlantSpec | null;
  fromHz?: number;
  toHz?: number | null;
  points?: number;
  signal?: "position" | "velocity" | "acceleration";
}

export interface SpectrumResult {
  frequencyHz: number[];
  magnitude: number[];
  unshaped: number[];
  modesHz: number[];
}

/** A zero of a profile's spectrum (`profileSpectrum`). */
export interface ProfileZero {
  frequencyHz: number;
  /** How many pulses vanish there (2: a tangent zero). */
  order: number;
  /** The final pulse (the rest of `duration`) is one of them. */
  finalPulse: boolean;
}

/** The frequencies of `profileSpectrum`. */
export interface SpectrumOptions {
  fromHz?: number;
  toHz: number;
  points?: number;
  signal?: "position" | "velocity" | "acceleration";
}

/** `profileSpectrum`'s result: |U(f)| of the profile and its zeros up to `toHz`. */
export interface ProfileSpectrum {
  frequencyHz: number[];
  magnitude: number[];
  zeros: ProfileZero[];
}

// ---------------------------------------------------------------------------------------------
// The printed corner (simulateCorner)

/** A toolpath in mm: a square from the origin, or Klipper's ringing tower's outline. */
export type PathSpec =
  | { kind: "square"; sideMm: number }
  | { kind: "ringingTower"; sideMm?: number; thicknessMm?: number };

export interface CornerAxisSpec {
  modes: PlantModeSpec[];
  shaper?: ShaperRequest | null;
  impulses?: Impulse[] | null;
}

export interface CornerSpec {
  path: PathSpec;
  /** mm/s */
  velocity: number;
  /** mm/s² */
  accel: number;
  /** Klipper's square_corner_velocity, mm/s (default 5). */
  squareCornerVelocity?: number;
  x: CornerAxisSpec;
  y: CornerAxisSpec;
  samplePeriodS?: number | null;
  settleS?: number | null;
  magnify?: number | null;
}

export interface CornerSegment {
  start: [number, number];
  end: [number, number];
  direction: [number, number];
  length: number;
  vStart: number;
  vCruise: number;
  vEnd: number;
  tStart: number;
  tAccel: number;
  tCruise: number;
  tDecel: number;
}

export interface CornerRinging {
  time: number;
  peakDeviation: number;
  ringing: number;
  windowS: number;
}

export interface CornerPrint {
  time: number[];
  nozzle: [number[], number[]];
  deviation: number[];
  corners: CornerRinging[];
  /** The track with the deviation magnified (when `magnify` was given). */
  drawn: [number[], number[]] | null;
}

export interface CornerResult {
  segments: CornerSegment[];
  duration: number;
  samplePeriodS: number;
  unshaped: CornerPrint;
  shaped: CornerPrint | null;
  shaperX: Shaper | null;
  shaperY: Shaper | null;
}

/** renderCorner's options. */
export interface CornerOptions {
  pixelRatio?: number | null;
  /** A label per shaper (default: the family's name). */
  labels?: string[] | null;
}

export interface CornerPrintNumbers {
  label: string;
  corners: CornerRinging[];
  /** Largest peak deviation over the corners (mm). */
  peakDeviation: number;
  /** Largest ringing over the corners (mm). */
  ringing: number;
}

/** renderCorner's result: the numbers of the prints it drew. */
export interface CornerFrame {
  duration: number;
  samplePeriodS: number;
  /** The path speed at each corner (mm/s). */
  junctionSpeeds: number[];
  unshaped: CornerPrintNumbers;
  shapers: CornerPrintNumbers[];
  /** Shapers that could not be designed: why. */
  leftOut: { label: string; index: number; field: string | null; message: string }[];
}

// ---------------------------------------------------------------------------------------------
// The playground frame

export interface PlaygroundView {
  fromHz?: number | null;
  toHz?: number | null;
  points?: number;
  vtol?: number;
  scv?: number;
  pixelRatio?: number;
  mismatch?: number;
  /** Per-mode ratio rᵢ (0.05 … 20): mode i's actual frequency is the model's × mismatch × rᵢ. */
  modeMismatch?: number[];
  /** Per-mode actual damping ratio (0 … 0.99); null: the model's. */
  actualDamping?: (number | null)[];
  command?: CommandSpec;
  plant?:
    | { kind: "modal" }
    | { kind: "twoMass"; baseMass: number; tipMass: number; stiffness: number; dampingCoefficient?: number }
    | { kind: "pendulum"; gravity?: number; initialAngle?: number; hoist?: CommandSpec | null };
  samples?: number;
  duration?: number | null;
  mapShaper?: number;
  seriesColors?: number[] | null;
  mapFrequencyPoints?: number;
  mapDampingPoints?: number;
  dampingTo?: number | null;
  dampingPoints?: number;
  spectrumPoints?: number;
}

export interface PlaygroundState {
  modes: ModeSpec[];
  shapers?: ShaperSpec[];
  shaper?: ShaperSpec | null;
  designed?: (ShaperInput | null)[];
  view?: PlaygroundView;
}

export interface PlaygroundCanvases {
  impulses?: HTMLCanvasElement;
  sensitivity?: HTMLCanvasElement;
  damping?: HTMLCanvasElement;
  map?: HTMLCanvasElement;
  response?: HTMLCanvasElement;
  command?: HTMLCanvasElement;
  spectrum?: HTMLCanvasElement;
  robustness?: HTMLCanvasElement;
}

export interface PlaygroundShaperResult {
  label: string;
  family: FamilyName;
  shaper: Shaper;
  sensitivity: SensitivityCurve;
  insensitivity: Insensitivity[];
  residualAtModes: number[];
  centroidDelay: number | null;
  klipper: KlipperFigures | null;
  simulation: Metrics | null;
  /** A `sampled` shaper's cost report (`sampledReport`'s figures); null for the other families
   * and for one passed in `designed` (a bounded one: its baseline needs the solver). */
  sampled: { rampDelay: number; cost: Cost; baselineCost: Cost; costReduction: number } | null;
}

export interface PlaygroundResult {
  results: PlaygroundShaperResult[];
  shaper: Shaper;
  sensitivity: SensitivityCurve;
  insensitivity: Insensitivity[];
  residualAtModes: number[];
  centroidDelay: number | null;
  simulation: {
    mismatch: number;
    plant: "modal" | "twoMass" | "pendulum";
    plantModesHz: number[];
    plantDamping: number[];
    duration: number;
    samplePeriod: number;
    samples: number;
    unshaped: Metrics;
  };
  robustness: RobustnessRow[];
  mapShaper: number;
  dampingTo: number;
}

// ---------------------------------------------------------------------------------------------
// Measured data

/** A signal: a `Float64Array`, a `Float32Array` or an array of numbers. */
export type Signal = Float64Array | Float32Array | number[];

export interface RecordingOptions {
  timeColumn?: string | null;
  timeScale?: number;
  fileName?: string | null;
  /** The channel a Klipper spectrum file's `psd` is (default `"sum"`). */
  channel?: "sum" | "x" | "y" | "z";
}

export interface RecordingChannel {
  name: string;
  values: Float64Array;
}

/** A recording (`parseRecording` of a Klipper raw, RepRapFirmware accelerometer or CSV
 * recording; RepRapFirmware's values in mm/s² on channels `accel_x` …). */
export interface Recording {
  format: "klipper" | "csv" | "rrf";
  timeColumn: string;
  sampleRateHz: number;
  startTimeS: number;
  durationS: number;
  rows: number;
  resampled: boolean;
  timing: { meanStepS: number; minStepS: number; maxStepS: number; jitter: number };
  channels: RecordingChannel[];
}

/** A Klipper spectrum file (`parseRecording` of `calibration_data_*.csv` or a resonances file). */
export interface SpectrumFile {
  format: "klipperResonances" | "klipperCalibration";
  fileName: string | null;
  axis: string | null;
  frequencyHz: Float64Array;
  psdX: Float64Array;
  psdY: Float64Array;
  psdZ: Float64Array;
  psdSum: Float64Array;
  psd: Float64Array;
  channel: "sum" | "x" | "y" | "z";
  normalization: "none" | "klipper";
  resolutionHz: number;
  even: boolean;
  rows: number;
  sources: number;
  shapers: { name: string; frequencyHz: number; values: Float64Array }[];
  extra: RecordingChannel[];
  runs: RecordingChannel[];
}

export type ParsedRecording = Recording | SpectrumFile;

export type WindowKind = "rectangular" | "hann" | "hamming" | "blackman" | "kaiser";
export type Detrend = "none" | "constant" | "linear";

export interface WelchOptions {
  sampleRateHz: number;
  segmentLength?: number | null;
  overlap?: number | null;
  window?: WindowKind;
  kaiserBeta?: number;
  symmetricWindow?: boolean;
  detrend?: Detrend;
  scaling?: "density" | "spectrum";
}

/** Klipper's Welch settings (`welch(signal, { preset: 'klipper', sampleRateHz })`). */
export interface KlipperWelchOptions {
  preset: "klipper";
  sampleRateHz: number;
}

export interface Psd {
  frequencyHz: Float64Array;
  psd: Float64Array;
  segmentLength: number;
  overlap: number;
  segments: number;
  resolutionHz: number;
  enbwBins: number;
  sampleRateHz: number;
}

export interface FftOptions {
  sampleRateHz: number;
  window?: WindowKind;
  kaiserBeta?: number;
  detrend?: Detrend;
}

export interface AmplitudeSpectrum {
  frequencyHz: Float64Array;
  magnitude: Float64Array;
  resolutionHz: number;
}

/** A spectrum to identify modes in or to rank shapers for. */
export interface SpectrumInput {
  frequencyHz: Signal;
  psd: Signal;
  normalization?: "none" | "klipper" | null;
  channel?: "sum" | "x" | "y" | "z" | null;
  segmentLength?: number | null;
  fileName?: string | null;
  axis?: string | null;
  psdX?: Signal | null;
  psdY?: Signal | null;
  psdZ?: Signal | null;
  psdSum?: Signal | null;
  runs?: { name: string; values: Signal }[] | null;
}

export interface IdentifyOptions {
  sampleRateHz?: number;
  signal?: "acceleration" | "velocity" | "position";
  maxModes?: number;
  minFrequencyHz?: number | null;
  maxFrequencyHz?: number | null;
  minProminenceDb?: number;
  segmentLength?: number | null;
  freeDecay?: boolean;
  /** For a recording: the channel, by name or index (default the first). */
  channel?: string | number | null;
}

export type IdentifyMethod = "halfPower" | "spectrumFit" | "freeDecay";

export interface ModeEstimate {
  method: IdentifyMethod;
  frequencyHz: number;
  damping: number;
  frequencyUncertaintyHz: number;
  dampingUncertainty: number;
}

export interface IdentifiedMode extends ModeEstimate {
  peakFrequencyHz: number;
  peakPsd: number;
  prominenceDb: number;
  estimates: ModeEstimate[];
}

export interface Identification {
  /** The channel's name (a recording), what the spectrum said, or `null` (a plain signal). */
  channel?: string | null;
  modes: IdentifiedMode[];
  spectrum: Psd;
  detectionSegmentLength: number;
  bandHz: [number, number];
  freeDecay: { startS: number; endS: number; levelDb: number } | null;
  /** The sweep read from a raw recording (its modes fitted on the whole record inside it), or
   * `null`: linear (f = f₀ + r·t, Klipper's resonance test) or exponential (f = f₀·e^(βt), a
   * logarithmic sine sweep), `rateHzPerS` the linear sweep's rate or the exponential one's at
   * the band's geometric centre √(f_lo·f_hi) (its rate at f is ∝ f). */
  sweep: { bandHz: [number, number]; rateHzPerS: number; law: 'linear' | 'exponential' } | null;
  /** A spectrum file's sweep end (the last bin fitted before its cliff), Hz, or `null`. */
  sweepEndHz: number | null;
  /** A response still rising where the sweep ends (a spectrum file's cliff, or the end of a
   * raw recording's `sweep`): a mode peaking near or past `frequencyHz` that the data do not
   * hold (its damping unknown; not one of `modes`), or `null`. */
  cutOff: { frequencyHz: number; prominenceDb: number } | null;
  /** What could not be identified, in words for the user (may be empty). */
  notes: string[];
}

export interface MeasuredMode {
  frequencyHz: number;
  damping?: number;
  frequencyUncertaintyHz?: number;
  dampingUncertainty?: number;
}

export interface RecommendOptions {
  families?: ShaperSpec[] | null;
  criterion?: "duration" | "klipper" | "optimal";
  maxRemainingVibration?: number;
  scv?: number;
  uncertaintySigmas?: number;
  minFrequencyHz?: number | null;
  maxFrequencyHz?: number | null;
  shapers?: string[] | null;
  dampingRatio?: number | null;
  maxSmoothing?: number | null;
  maxVibrations?: number | null;
  testDampingRatios?: number[] | null;
  shaperFrequencies?: number[] | null;
  shaperFrequencyRange?: { start?: number | null; end?: number | null; step?: number | null } | null;
  firmware?: "klipper" | "kalico" | "reprapfirmware" | "dangerklipper" | "danger-klipper" | "rrf";
}

export interface Candidate {
  label: string;
  /** A family name, or Klipper's (`"2hump_ei"`, `"3hump_ei"`) for `criterion: 'klipper'`. */
  family: string;
  spec: ShaperSpec;
  modes: { frequencyHz: number; damping: number }[];
  shaper: Shaper;
  durationS: number;
  remainingVibration: number;
  nominalRemainingVibration: number;
  smoothing: number | null;
  maxAccel: number | null;
  klipperScore: number | null;
  acceptable: boolean;
  /** `criterion: 'optimal'`: `"klipper"`, `"mainline"` or `"custom"`. */
  kind?: string;
}

export interface KlipperFitPoint {
  freq: number;
  vibrs: number;
  smoothing: number;
  score: number;
  maxAccel: number;
}

/** Klipper's table (`criterion: 'klipper'`). */
export interface KlipperFit {
  best: number;
  families: {
    name: string;
    pick: KlipperFitPoint;
    printed: { freq: number; vibrationsPercent: number; smoothing: number; maxAccel: number };
    shaper: Shaper;
    freqBins: number[];
    vals: number[];
  }[];
  unknown: string[];
  dampingRatio: number;
  testDampingRatios: number[];
  maxFreq: number;
}

export interface Recommendation {
  criterion: "duration" | "klipper" | "optimal";
  recommended: number;
  ranked: Candidate[];
  skipped: { label: string; reason: string }[];
  dampingTested: number[];
  frequencyFactors: number[];
  bandHz: [number, number];
  klipper?: KlipperFit;
  note?: string;
}

export interface DrawSpectrumOptions {
  peaksHz?: number[];
  maxHz?: number | null;
  pixelRatio?: number | null;
  title?: string | null;
  yLabel?: string | null;
}

export interface KlipperChartData {
  frequencyHz: Signal;
  psdSum: Signal;
  psdX?: Signal | null;
  psdY?: Signal | null;
  psdZ?: Signal | null;
  shapers?: { values: Signal; color?: string; selected?: boolean; dotted?: boolean }[];
  after?: Signal | null;
}

export interface KlipperChartOptions {
  maxHz?: number | null;
  pixelRatio?: number | null;
  title?: string | null;
}

/** One axis of `firmwareConfig` (crate::export::firmware::AxisShaper). */
export interface AxisShaper {
  axis: string;
  family: string;
  frequencyHz?: number | null;
  damping?: number;
  impulses?: Impulse[] | null;
  maxAccel?: number | null;
  modes?: ModeSpec[];
}

export interface FirmwareConfigRequest {
  firmware: "klipper" | "klipperCommand" | "kalico" | "kalicoCommand" | "rrf" | "marlin";
  axes: AxisShaper[];
}

export interface FirmwareConfig {
  text: string;
  warnings: string[];
}
