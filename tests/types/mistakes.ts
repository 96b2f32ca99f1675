// Deliberate mistakes: each must fail to compile against pkg/input_shaping.d.ts. Each is one
// statement on the line after its `// @ts-expect-error TSnnnn` (tsc --strict fails if a marked
// line compiles); tests/types/types.test.mjs also compiles this file with the markers removed
// and requires each marked line, and no other, to fail with the error code its marker names.
import {
  design,
  residualVibration,
  sensitivity,
  insensitivity,
  robustnessTable,
  exportShaper,
  quantize,
  realizeShaper,
  simulate,
  spectrum,
  renderPlayground,
  parseRecording,
  welch,
  identifyModes,
  recommendShaper,
  firmwareConfig,
  families,
} from "../../pkg/input_shaping.js";
import type { DesignSpec, InputShapingError, Shaper, ShaperSpec } from "../../pkg/input_shaping.js";

declare const shaper: Shaper;
const mode = { frequencyHz: 2, damping: 0.05 };

// A family that does not exist.
// @ts-expect-error TS2322
design({ family: "ei9", modes: [mode] });
// A misspelt field of a mode.
// @ts-expect-error TS2561
design({ family: "zv", modes: [{ frequencyHZ: 2 }] });
// A number where a string goes.
// @ts-expect-error TS2322
exportShaper(shaper, { format: 1 });
// A string where a number goes.
// @ts-expect-error TS2322
design({ family: "ei", vtol: "0.05", modes: [mode] });
// A required field missing: the modes.
// @ts-expect-error TS2345
design({ family: "zvd" });
// A required parameter missing: `humps` of eihump.
// @ts-expect-error TS2345
design({ family: "eihump", modes: [mode] });
// A parameter of another family.
// @ts-expect-error TS2353
design({ family: "zv", vtol: 0.05, modes: [mode] });
// A select parameter's value that is not one of its options.
// @ts-expect-error TS2322
design({ family: "sampled", periodS: 0.01, impulses: 20, objective: "fastest", modes: [mode] });
// A fixed-length band given as one number.
// @ts-expect-error TS2322
design({ family: "si", bandHz: 1, modes: [mode] });
// A vtol that is not a number.
// @ts-expect-error TS2345
insensitivity(shaper, mode, "0.05");
// A mode without its frequency.
// @ts-expect-error TS2345
residualVibration(shaper, { damping: 0.05 });
// Options with a misspelt field.
// @ts-expect-error TS2561
sensitivity(shaper, { fromHz: 0, toHz: 4, point: 100 });
// A result's field that does not exist.
// @ts-expect-error TS2551
const d: number = design({ family: "zv", modes: [mode] }).durationS;
// A robustness table spec with an unknown family.
// @ts-expect-error TS2322
robustnessTable(mode, 0.05, [{ family: "zz" }]);
// A quantize method that does not exist.
// @ts-expect-error TS2322
quantize(shaper, mode, { amplitudeSteps: 255, method: "round" });
// A firmware that does not exist.
// @ts-expect-error TS2322
realizeShaper({ family: "zv", modes: [mode] }, { firmware: "smoothieware" });
// A command kind that does not exist.
// @ts-expect-error TS2322
simulate({ plant: { kind: "modal", modes: [mode] }, command: { kind: "jump" } });
// A trapezoid without its max velocity.
// @ts-expect-error TS2322
simulate({ plant: { kind: "vecianaTestBed" }, command: { kind: "trapezoid", distance: 1, maxAcceleration: 4 } });
// A plant kind that does not exist.
// @ts-expect-error TS2322
simulate({ plant: { kind: "spring" }, command: { kind: "step" } });
// A profile shape that does not exist.
// @ts-expect-error TS2322
spectrum({ command: { kind: "profile", shape: "square", frequencyHz: 1, distance: 1, duration: 2 } });
// A spectrum signal that does not exist.
// @ts-expect-error TS2322
spectrum({ command: { kind: "step" }, signal: "jerk" });
// The playground without its modes.
// @ts-expect-error TS2345
renderPlayground({ shapers: [{ family: "zv" }] });
// A recording that is not a string.
// @ts-expect-error TS2345
parseRecording(123);
// A Welch window that does not exist.
// @ts-expect-error TS2322
welch([1, 2, 3], { sampleRateHz: 100, window: "triangle" });
// A signal of strings.
// @ts-expect-error TS2322
identifyModes(["1", "2"], { sampleRateHz: 100 });
// A recommendation criterion that does not exist.
// @ts-expect-error TS2322
recommendShaper({ frequencyHz: [1], psd: [1] }, [], { criterion: "best" });
// A firmware that does not exist.
// @ts-expect-error TS2322
firmwareConfig({ firmware: "grbl", axes: [] });
// A family name from the table is not any string.
// @ts-expect-error TS2322
const name: "zz" = families()[0].name;
// An error kind that does not exist.
// @ts-expect-error TS2367
const isOops = (e: InputShapingError) => e.kind === "oops";
// A spec value narrowed by its family has that family's parameters only.
declare const spec: DesignSpec;
// @ts-expect-error TS2339
if (spec.family === "zv") console.log(spec.vtol);
// A shaper spec is not a design spec: the modes are missing.
declare const bare: ShaperSpec;
// @ts-expect-error TS2322
const full: DesignSpec = bare;

console.log(d, name, isOops, full);
