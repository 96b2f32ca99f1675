// A TypeScript program using the JavaScript API as a user would (docs/js-api.md,
// *TypeScript*). `npm test` compiles it with `tsc --strict --noEmit` against the generated
// pkg/input_shaping.d.ts (tests/types/types.test.mjs); it is not run.
import init, {
  design,
  residualVibration,
  sensitivity,
  insensitivity,
  sensitivityMap,
  dampingSensitivity,
  dampingInsensitivity,
  robustnessTable,
  families,
  exportShaper,
  klipperFigures,
  rampDelay,
  sampledReport,
  quantize,
  realizeShaper,
  simulate,
  spectrum,
  profileSpectrum,
  simulateCorner,
  renderCorner,
  renderPlayground,
  parseRecording,
  RecordingParser,
  welch,
  fftSpectrum,
  identifyModes,
  recommendShaper,
  drawSpectrum,
  drawKlipperChart,
  firmwareConfig,
} from "../../pkg/input_shaping.js";
import type {
  DesignSpec,
  FamilyName,
  InputShapingError,
  ModeSpec,
  Shaper,
  ShaperSpec,
  SimulationResult,
} from "../../pkg/input_shaping.js";

export async function main(canvas: HTMLCanvasElement): Promise<void> {
  await init();
  const mode: ModeSpec = { frequencyHz: 2, damping: 0.05 };

  // Design: the spec is a union discriminated by `family`; each family has its parameters.
  const zvd: Shaper = design({ family: "zvd", modes: [mode] });
  const ei = design({ family: "ei", vtol: 0.05, modes: [mode] });
  const si = design({
    family: "si",
    modes: [{ frequencyHz: 1, damping: 0.1 }],
    bandHz: [0.7, 1.3],
    dampingRange: [0, 0.2],
  });
  const sampled = design({ family: "sampled", periodS: 0.012, impulses: 36, delaySamples: 17, modes: [mode] });
  const custom = design({
    family: "custom",
    impulses: [{ time: 0, amplitude: 0.5 }, { time: 0.25, amplitude: 0.5 }],
    normalize: true,
    modes: [mode],
  });
  const first: number = zvd.impulses[0].time + ei.duration + si.impulses.length + sampled.duration + custom.duration;
  // A solved family's design says whether its polish converged (absent for the others).
  const polished: boolean | undefined = si.solver?.polished;
  console.log(polished, si.solver?.rounds, si.solver?.programs);

  // A spec built elsewhere, narrowed by its family.
  const spec: DesignSpec = { family: "eihump", humps: 3, modes: [mode] };
  if (spec.family === "eihump") {
    const humps: number = spec.humps;
    console.log(humps);
  }

  // Analysis.
  const v: number = residualVibration(zvd, { frequencyHz: 2.2, damping: 0.05 });
  const curve = sensitivity(zvd, { fromHz: 0, toHz: 4, points: 200 });
  const band = insensitivity(zvd, mode, 0.05);
  const map = sensitivityMap(zvd, {
    fromHz: 0,
    toHz: 4,
    frequencyPoints: 50,
    dampingFrom: 0,
    dampingTo: 0.2,
    dampingPoints: 10,
  });
  const grid: Float64Array = map.vibration;
  const dcurve = dampingSensitivity(zvd, { frequencyHz: 2, fromDamping: 0, toDamping: 0.3, points: 30 });
  const dband = dampingInsensitivity(zvd, mode, 0.05);
  const rows = robustnessTable(mode, 0.05);
  const some = robustnessTable(mode, 0.05, [{ family: "zv" }, { family: "ei2", vtol: 0.1 }]);
  console.log(v, curve.vibration[0], band.width, grid[0], dcurve.damping[0], dband.highDamping, rows[0].durationPeriods, some[1].spec.family);

  // The family table: names are the spec's `family` values.
  const names: FamilyName[] = families().map((f) => f.name);
  const noParams: ShaperSpec[] = families()
    .filter((f) => f.params.length === 0)
    .map((f) => ({ family: f.name }) as ShaperSpec);
  console.log(names, noParams);

  const csv: string = exportShaper(zvd, { format: "csv" });
  const figures = klipperFigures(zvd);
  const accel: number | null = figures.maxAccel;
  const tau: number = rampDelay(zvd, mode);
  const report = sampledReport({ family: "sampled", periodS: 0.012, impulses: 36, modes: [mode] });
  const rounded = quantize(zvd, mode, { amplitudeSteps: 255, method: "largestRemainder" });
  console.log(csv, accel, tau, report.cost.total, rounded.insensitivityAfter.width, first);
  const onFtMotion = realizeShaper({ family: "zv", modes: [mode] }, { firmware: "marlinFtMotion" });
  const hz: number | null = onFtMotion.actsAsHz;
  console.log(onFtMotion.summary, onFtMotion.changes[0]?.kind, onFtMotion.modes[0].vibrationRealised, hz);

  // Simulation: plants discriminated by `kind`, commands by `kind` (and profiles by `shape`).
  const sim: SimulationResult = simulate({
    plant: { kind: "modal", modes: [{ frequencyHz: 1.2, damping: 0.012 }, { frequencyHz: 3.4, damping: 0.013 }] },
    command: { kind: "trapezoid", distance: 1, maxVelocity: 1, maxAcceleration: 4 },
    shaper: { family: "zvd" },
    sampleRateHz: 1000,
  });
  const residual: number | null = sim.shaped ? sim.shaped.metrics.residualVibrationPercent : null;
  const crane = simulate({
    plant: { kind: "pendulum", length: 1 },
    command: { kind: "profile", shape: "triangle", frequencyHz: 0.5, distance: 1, duration: 4 },
  });
  const swing: number[] | undefined = crane.unshaped.swingAngle;
  const u = spectrum({ command: { kind: "step" }, shaper: { family: "zv", modes: [mode] }, toHz: 10 });
  const ps = profileSpectrum({ kind: "profile", shape: "pulse", frequencyHz: 2, distance: 1, duration: 1 }, { toHz: 10 });
  const firstZero: number = ps.zeros[0].frequencyHz + ps.zeros[0].order + (ps.zeros[0].finalPulse ? 1 : 0) + ps.magnitude[0];
  void firstZero;
  console.log(residual, swing, u.magnitude[0]);

  // The printed corner: a path discriminated by `kind`, each axis with its modes and shaper.
  const print = simulateCorner({
    path: { kind: "ringingTower" },
    velocity: 100,
    accel: 3000,
    x: { modes: [{ frequencyHz: 42, damping: 0.06 }], shaper: { family: "mzv" } },
    y: { modes: [{ frequencyHz: 55, damping: 0.05 }], impulses: [{ time: 0, amplitude: 1 }] },
    magnify: 50,
  });
  const ringing: number | undefined = print.shaped?.corners[0].ringing;
  const drawn: [number[], number[]] | null = print.unshaped.drawn;
  console.log(ringing, drawn, print.segments[1].vStart, print.shaperX?.duration);
  const cornerFrame = renderCorner(
    { path: { kind: "square", sideMm: 40 }, velocity: 150, accel: 5000, x: { modes: [mode] }, y: { modes: [mode] } },
    [{ family: "zv" }, { family: "ei", vtol: 0.05 }],
    canvas,
    { pixelRatio: 2, labels: ["ZV", "EI"] },
  );
  console.log(cornerFrame.shapers[0].ringing, cornerFrame.leftOut.length, cornerFrame.junctionSpeeds[0]);

  // The playground frame.
  const frame = renderPlayground(
    { modes: [mode], shapers: [{ family: "zv" }, { family: "ei" }], view: { vtol: 0.05, plant: { kind: "modal" } } },
    { sensitivity: canvas },
  );
  console.log(frame.results[1].label, frame.simulation.plant, frame.robustness.length);

  // Measured data.
  const parsed = parseRecording("#time,accel_x\n0,0\n0.001,1\n", { fileName: "raw.csv" });
  if ("channels" in parsed) {
    const values: Float64Array = parsed.channels[0].values;
    const psd = welch(values, { sampleRateHz: parsed.sampleRateHz, window: "hann" });
    const klipperPsd = welch(values, { preset: "klipper", sampleRateHz: parsed.sampleRateHz });
    const fft = fftSpectrum(values, { sampleRateHz: parsed.sampleRateHz });
    const id = identifyModes(parsed, { channel: "accel_x", maxModes: 2 });
    const pick = recommendShaper(id.spectrum, id.modes, { criterion: "klipper" });
    drawSpectrum(canvas, psd, { peaksHz: id.modes.map((m) => m.frequencyHz) });
    drawKlipperChart(canvas, { frequencyHz: psd.frequencyHz, psdSum: psd.psd }, { maxHz: 200 });
    const law: 'linear' | 'exponential' | undefined = id.sweep?.law;
    console.log(klipperPsd.enbwBins, fft.resolutionHz, pick.ranked[pick.recommended].label, id.sweep?.rateHzPerS, law);
  } else {
    const fromFile = identifyModes(parsed);
    console.log(parsed.shapers.map((s) => s.name), fromFile.modes.length);
  }
  const parser = new RecordingParser({ timeScale: 1 });
  parser.push("#time,accel_x\n");
  const done = parser.finish();
  console.log(done.format, parser.lines);

  const config = firmwareConfig({ firmware: "klipper", axes: [{ axis: "x", family: "zvd", frequencyHz: 40 }] });
  console.log(config.text, config.warnings);

  // Errors: a JS Error with `kind` and `field`.
  try {
    design({ family: "zv", modes: [{ frequencyHz: 2, damping: 1.5 }] });
  } catch (e) {
    const error = e as InputShapingError;
    if (error.kind === "invalid") console.log(error.field, error.message);
  }
}
