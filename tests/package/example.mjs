// The example program of the installed package (package.test.mjs copies it into an empty
// project that installed the tarball): read a recording, identify its mode, design a shaper
// for it, analyse the shaper and simulate a move. The same file runs in Node, in esbuild's
// bundles and in a browser, imported and initialised the same way everywhere.
import init, {
  parseRecording, identifyModes, design, residualVibration, insensitivity, simulate,
} from 'input-shaping';

/** The true mode of the synthetic recording: what identification must find. */
export const TRUE_MODE = { frequencyHz: 40, damping: 0.03 };

/** A CSV recording of the free decay of TRUE_MODE: x(t) = e^(−ζωt) cos(ω_d t), 1 kHz, 3 s. */
export function decayCsv() {
  const { frequencyHz: f, damping: z } = TRUE_MODE;
  const rate = 1000;
  const w = 2 * Math.PI * f;
  const wd = w * Math.sqrt(1 - z * z);
  const lines = ['time,accel_x'];
  for (let i = 0; i < 3 * rate; i++) {
    const t = i / rate;
    lines.push(`${t},${Math.exp(-z * w * t) * Math.cos(wd * t)}`);
  }
  return lines.join('\n');
}

export async function run() {
  await init();
  const recording = parseRecording(decayCsv(), { fileName: 'decay.csv' });
  const identified = identifyModes(recording);
  const { frequencyHz, damping } = identified.modes[0];
  const mode = { frequencyHz, damping };
  const shaper = design({ family: 'zvd', modes: [mode] });
  const move = simulate({
    plant: { kind: 'modal', modes: [TRUE_MODE] },
    command: { kind: 'trapezoid', distance: 1, maxVelocity: 10, maxAcceleration: 2000 },
    shaper: { family: 'zvd', modes: [mode] },
  });
  let error = null;
  try {
    design({ family: 'zvd', modes: [{ frequencyHz: 2, damping: 1.5 }] });
  } catch (e) {
    error = { isError: e instanceof Error, kind: e.kind, field: e.field };
  }
  return {
    sampleRateHz: recording.sampleRateHz,
    modes: identified.modes.length,
    mode,
    impulses: shaper.impulses,
    vibrationAtTrueMode: residualVibration(shaper, TRUE_MODE),
    band: insensitivity(shaper, mode, 0.05),
    unshapedResidualPercent: move.unshaped.metrics.residualVibrationPercent,
    shapedResidualPercent: move.shaped.metrics.residualVibrationPercent,
    error,
  };
}
