// The measured-data worker: reads recordings in chunks, identifies the modes and ranks the
// shapers off the page's thread, so a 10⁶-row file never freezes the page. Messages in:
// { type: 'module', module, recordingModule } (first: the page's compiled wasm module and the
// recording module, compiled by the page's measured-data view), { id, type: 'load', files,
// options }, { id, type: 'analyse', options } and { id, type: 'fft', channel }; out: progress,
// result ({ recording, identification, recommendation, rankingError, axes }), fft
// ({ spectrum }) or error ({ message, file, line, column }). Reading and identifying use the
// worker's own small module (pkg/page/recording.js); the ranking designs every candidate
// shaper.
//
// `axes`: one entry per machine axis (from the file names: Klipper writes
// raw_data_<axis>_…, resonances_<axis>_…, calibration_data_<axis>_…), each with Klipper's
// spectrum (PSD of x, y, z and their sum; several files of one axis combined as
// calibrate_shaper.py combines them), Klipper's table (recommendShaper, criterion 'klipper'),
// the optimised rows where the page's module has them, and the shaper curves a calibration
// file carries. The ranking is in the worker's own module too (recommendShaper moved there
// with Klipper's fit, off the page's first load); the page still hands over its own module.
import initRecording, { RecordingParser, identifyModes, fftSpectrum, welch, recommendShaper } from '../pkg/page/recording.js';
import initPlayground from '../pkg/page/playground.js';

const CHUNK_BYTES = 1 << 20;
let ready = null; // the recording module, instantiated here
let designs = null; // the page's module, instantiated here
let recording = null; // the last good raw recording (modes, FFT)
let loaded = null; // the last good files, parsed: [{ name, rec }]

function summary(r) {
  const { channels, ...rest } = r;
  return { ...rest, channels: (channels ?? []).map((c) => c.name) };
}

async function read(id, file, done, total) {
  const parser = new RecordingParser({ fileName: file.name });
  const decoder = new TextDecoder('utf-8');
  try {
    for (let offset = 0; offset < file.size; offset += CHUNK_BYTES) {
      const bytes = await file.slice(offset, offset + CHUNK_BYTES).arrayBuffer();
      parser.push(decoder.decode(bytes, { stream: true }));
      const fraction = (done + offset + bytes.byteLength) / Math.max(1, total);
      postMessage({ id, type: 'progress', fraction: Math.min(1, fraction), rows: parser.rows, file: file.name });
    }
    parser.push(decoder.decode());
    return parser.finish();
  } finally {
    parser.free();
  }
}

// ---- Klipper's spectra ---------------------------------------------------------------------

/** The machine axis a Klipper file is for, from its name (`resonances_x_…`), or null. */
function axisOf(name, rec) {
  const m = /(?:^|[\\/])(?:raw_data|resonances|calibration_data)_([a-z0-9]+?)_/i.exec(name)
    ?? /(?:^|[_\-. ])([xyz])(?:[_\-. ]|$)/i.exec(name.replace(/\.[^.]*$/, ''));
  return (m?.[1] ?? rec?.axis ?? rec?.spectrum?.axis ?? null)?.toLowerCase() ?? null;
}

/** Whether a parsed file is a spectrum (resonances or calibration data) rather than samples. */
function spectrumOf(rec) {
  const s = rec.spectrum ?? (rec.psdSum || rec.psd_xyz ? rec : null);
  if (!s) return null;
  const f = s.frequencyHz ?? s.freq;
  const sum = s.psdSum ?? s.psd_xyz ?? s.psd;
  return f && sum ? { s, f, sum } : null;
}

/**
 * Klipper's `normalize_to_frequencies`, for the chart only (the ranking normalises in Rust,
 * crate/measure/klipper/data.rs `normalize`, the same operations in the same order): P / (f + 0.1),
 * and below 10 Hz × e^{1 − (10/(f + 0.1))²}.
 */
function normalize(psd, f) {
  return Float64Array.from(psd, (p, i) => {
    let v = p / (f[i] + 0.1);
    if (f[i] < 10) { const r = 10 / (f[i] + 0.1); v *= Math.exp(-(r * r) + 1); }
    return v;
  });
}

/**
 * Klipper's spectrum of one parsed file: { frequencyHz, psdX, psdY, psdZ, psdSum, normalized,
 * fitted } — the PSDs as read (a raw recording's by Klipper's procedure), `normalized` when
 * they are Klipper-normalised already (calibration files).
 */
function klipperSpectrum(name, rec) {
  const spec = spectrumOf(rec);
  if (spec) {
    const { s, f } = spec;
    const normalized = s.normalization === 'klipper' || s.normalized === true;
    const copy = (p) => (p?.length === f.length ? Float64Array.from(p) : null);
    const fitted = (rec.shapers ?? s.shapers ?? []).map((c) => ({
      name: c.name ?? c.family, freq: c.frequencyHz ?? c.freq, values: c.values ?? c.vals,
    })).filter((c) => c.values?.length === f.length);
    return {
      frequencyHz: Float64Array.from(f), psdX: copy(s.psdX), psdY: copy(s.psdY), psdZ: copy(s.psdZ),
      psdSum: copy(spec.sum), normalized, fitted,
    };
  }
  // Raw samples: Klipper's process_accelerometer_data — Welch with its settings per axis and
  // the sum of the three (calibrate_shaper.py normalises them afterwards).
  const channels = rec.channels ?? [];
  const pick = (axis) => channels.find((c) => new RegExp(`(^|_)${axis}$`, 'i').test(c.name));
  const xyz = ['x', 'y', 'z'].map(pick);
  const used = xyz.some(Boolean) ? xyz : [channels[0], null, null];
  // Klipper's sampling rate: N / (t_last − t_first).
  const fs = rec.rows > 1 && rec.durationS > 0 ? rec.rows / rec.durationS : rec.sampleRateHz;
  const psds = used.map((c) => (c ? welch(c.values, { preset: 'klipper', sampleRateHz: fs }) : null));
  const f = psds.find(Boolean).frequencyHz;
  const sum = new Float64Array(f.length);
  for (const p of psds) if (p) p.psd.forEach((v, i) => { sum[i] += v; });
  const [px, py, pz] = psds.map((p) => (p ? p.psd : null));
  return { frequencyHz: f, psdX: px, psdY: py, psdZ: pz, psdSum: sum, normalized: false, fitted: [] };
}

/** `p` (on bins `fx`) linearly interpolated onto the bins `f`. */
function interp(fx, p, f) {
  if (fx === f || (fx.length === f.length && fx.every((x, i) => x === f[i]))) return p;
  let j = 1;
  return Float64Array.from(f, (x) => {
    while (j < fx.length - 1 && fx[j] < x) j++;
    const t = Math.min(1, Math.max(0, (x - fx[j - 1]) / (fx[j] - fx[j - 1] || 1)));
    return p[j - 1] + t * (p[j] - p[j - 1]);
  });
}

const KEYS = ['psdX', 'psdY', 'psdZ', 'psdSum'];

/**
 * One axis's files: `rank`, the spectrum recommendShaper reads (several runs kept apart in
 * `runs`, as Klipper's CalibrationData.add_data keeps them, on the first file's bins; normalised
 * in Rust unless every file is), and `chart`, the normalised PSDs drawn (the mean over the runs).
 */
function axisSpectrum(spectra) {
  const [first] = spectra;
  const f = first.frequencyHz;
  const same = spectra.every((s) => s.normalized === first.normalized);
  // Runs of mixed normalisation: normalise the others here, then all count as normalised.
  const norm = (s, p) => (!same && !s.normalized ? normalize(p, s.frequencyHz) : p);
  const on = (s, key) => (s[key] ? interp(s.frequencyHz, norm(s, s[key]), f) : null);
  const mean = (key) => {
    if (spectra.some((s) => !s[key])) return null;
    const m = new Float64Array(f.length);
    for (const s of spectra) on(s, key).forEach((v, i) => { m[i] += v / spectra.length; });
    return m;
  };
  const rank = { frequencyHz: f, normalization: !same || first.normalized ? 'klipper' : 'none' };
  for (const key of KEYS) rank[key] = mean(key);
  if (spectra.length > 1) rank.runs = spectra.map((s, i) => ({ name: s.name ?? `run ${i + 1}`, values: on(s, 'psdSum') }));
  const chart = { frequencyHz: f, fitted: spectra.flatMap((s) => s.fitted) };
  for (const key of KEYS) chart[key] = rank[key] && (rank.normalization === 'klipper' ? rank[key] : normalize(rank[key], f));
  return { rank, chart };
}

/**
 * V(f) of an impulse sequence as Klipper's figure draws it: the largest over its test damping
 * ratios 0.075, 0.1, 0.15 of |Σ Aᵢ e^{−ζω(T−tᵢ)} e^{iω_d tᵢ}| / Σ Aᵢ (shaper_calibrate.py,
 * `_estimate_shaper` and `_estimate_remaining_vibrations`). Used only when the ranking does not
 * give the curve itself.
 */
function shaperCurve(impulses, f) {
  const sumA = impulses.reduce((s, p) => s + p.amplitude, 0);
  const end = impulses[impulses.length - 1].time;
  return Float64Array.from(f, (x) => {
    let worst = 0;
    for (const z of [0.075, 0.1, 0.15]) {
      const w = 2 * Math.PI * x;
      const wd = w * Math.sqrt(1 - z * z);
      let s = 0;
      let c = 0;
      for (const p of impulses) {
        const a = p.amplitude * Math.exp(-z * w * (end - p.time));
        s += a * Math.sin(wd * p.time);
        c += a * Math.cos(wd * p.time);
      }
      worst = Math.max(worst, Math.hypot(s, c) / sumA);
    }
    return worst;
  });
}

/** `values` at `bins`, read at the frequencies `f` (linear between bins, the end values beyond). */
function onBins(values, bins, f) {
  if (!bins || bins.length !== values.length || (bins.length === f.length && bins.every((b, i) => b === f[i]))) return values;
  let j = 0;
  return Float64Array.from(f, (x) => {
    while (j < bins.length - 1 && bins[j + 1] < x) j++;
    if (x <= bins[0]) return values[0];
    if (j >= bins.length - 1) return values[bins.length - 1];
    const t = (x - bins[j]) / (bins[j + 1] - bins[j]);
    return values[j] + Math.min(1, Math.max(0, t)) * (values[j + 1] - values[j]);
  });
}

/** One row of Klipper's table from a ranked candidate (or a family's fit, `{ name, pick, vals }`). */
function row(c, f) {
  const p = c.pick ?? c;
  const given = c.values ?? c.vals;
  const values = given ? onBins(given, c.freqBins ?? c.frequencyHz, f)
    : c.shaper?.impulses ? shaperCurve(c.shaper.impulses, f) : null;
  return {
    label: c.label ?? c.name ?? c.family,
    name: c.name ?? c.family,
    kind: c.kind ?? c.firmware ?? null,
    freq: p.freq ?? p.frequencyHz ?? c.spec?.frequencyHz ?? c.modes?.[0]?.frequencyHz ?? NaN,
    damping: p.dampingRatio ?? c.dampingRatio ?? c.damping ?? c.spec?.damping ?? c.modes?.[0]?.damping ?? NaN,
    vibrations: p.vibrations ?? p.vibrs ?? c.remainingVibration,
    smoothing: p.smoothing,
    maxAccel: p.maxAccel,
    score: p.score ?? c.klipperScore,
    values: values?.length === f.length ? Float64Array.from(values) : null,
    shaper: c.shaper ?? null,
  };
}

const CHANNEL_KEY = { sum: 'psdSum', x: 'psdX', y: 'psdY', z: 'psdZ' };

/** Klipper's table (and the optimised rows, where available) for one axis. */
function rankAxis(axis, { rank, chart }, channel) {
  const f = chart.frequencyHz;
  const psd = rank[CHANNEL_KEY[channel]] ?? rank.psdSum;
  const input = { ...rank, psd, channel: rank[CHANNEL_KEY[channel]] ? channel : 'sum' };
  const out = { axis, spectrum: chart, channel: input.channel, klipper: null, optimal: null, error: null };
  try {
    const rec = recommendShaper(input, [], { criterion: 'klipper' });
    const fit = rec.klipper;
    out.klipper = fit
      ? { rows: fit.families.map((c) => ({ ...row(c, f), damping: fit.dampingRatio })), selected: fit.best }
      : { rows: rec.ranked.map((c) => row(c, f)), selected: rec.recommended };
  } catch (e) {
    out.error = e?.message ?? String(e);
  }
  try {
    const opt = recommendShaper(input, [], { criterion: 'optimal', firmware: 'klipper' });
    const rows = opt.rows ?? opt.table ?? opt.ranked;
    if (rows?.length) out.optimal = { rows: rows.map((c) => row(c, f)), selected: opt.recommended ?? 0, note: opt.note ?? '' };
  } catch {
    // 'optimal' is not in this module's ranking (yet): the table shows Klipper's rows only.
  }
  return out;
}

/** Files grouped per axis; each group's spectrum, ranked. */
function klipperAxes(files, options, modes, modesFile) {
  const groups = new Map();
  for (const { name, rec } of files) {
    const axis = axisOf(name, rec) ?? name;
    if (!groups.has(axis)) groups.set(axis, []);
    groups.get(axis).push({ name, rec });
  }
  return [...groups].map(([axis, list]) => {
    const spectra = list.map(({ name, rec }) => ({ ...klipperSpectrum(name, rec), name }));
    const ranked = rankAxis(axis, axisSpectrum(spectra), options.psdChannel ?? 'sum');
    const own = list.some(({ name }) => name === modesFile) ? modes : null;
    return { ...ranked, files: list.map((x) => x.name), formats: list.map((x) => x.rec.format), modes: own ?? [] };
  });
}

// ---- modes of the first raw recording (as before) ------------------------------------------

function identify(rec, options) {
  const identification = identifyModes(rec, options);
  let recommendation = null;
  let rankingError = null;
  if (identification.modes.length > 0) {
    try {
      recommendation = recommendShaper(identification.spectrum, identification.modes, {});
    } catch (e) {
      rankingError = e?.message ?? String(e); // the modes stay shown; only the ranking is missing
    }
  }
  return { identification, recommendation, rankingError };
}

function analyse(id, files, options) {
  const raw = files.find(({ rec }) => rec.channels && rec.sampleRateHz);
  let primary = null;
  let identificationError = null;
  const first = raw ?? files[0];
  if (first) {
    postMessage({ id, type: 'analysing', rows: first.rec.rows ?? 0 });
    try {
      primary = identify(first.rec, options.identify);
    } catch (e) {
      if (raw) throw e;
      identificationError = e?.message ?? String(e); // a spectrum the identification cannot read yet
    }
  }
  const axes = klipperAxes(files, options, primary?.identification?.modes, first?.name);
  return {
    id, type: 'result', recording: first ? summary(first.rec) : null, file: first?.name, raw: Boolean(raw),
    ...(primary ?? { identification: null, recommendation: null, rankingError: null }), identificationError, axes,
  };
}

onmessage = async ({ data }) => {
  const { id } = data;
  if (data.type === 'module') {
    ready = initRecording(data.recordingModule ? { module_or_path: data.recordingModule } : undefined);
    designs = initPlayground(data.module ? { module_or_path: data.module } : undefined);
    return;
  }
  let file = null;
  try {
    await (ready ??= initRecording());
    await (designs ??= initPlayground()); // without the page's module, fetch it
    if (data.type === 'load') {
      const list = [];
      const total = data.files.reduce((s, x) => s + x.size, 0);
      let done = 0;
      for (const f of data.files) {
        file = f.name;
        list.push({ name: f.name, rec: await read(id, f, done, total) });
        done += f.size;
      }
      file = null;
      const result = analyse(id, list, data.options);
      // Only once everything worked: a bad file leaves the last good result.
      loaded = list;
      recording = list.find(({ rec }) => rec.channels && rec.sampleRateHz)?.rec ?? null;
      postMessage(result);
    } else if (data.type === 'analyse' && loaded) {
      postMessage(analyse(id, loaded, data.options));
    } else if (data.type === 'fft' && recording) {
      // The plain FFT magnitude of the whole channel (at most 2^22 samples), as |X|² for the chart.
      const values = recording.channels[data.channel]?.values ?? recording.channels[0].values;
      const s = fftSpectrum(values, { sampleRateHz: recording.sampleRateHz });
      const power = s.magnitude.map((m) => m * m);
      postMessage({ id, type: 'fft', spectrum: { frequencyHz: s.frequencyHz, psd: power } }, [power.buffer]);
    }
  } catch (e) {
    postMessage({ id, type: 'error', file, message: e?.message ?? String(e), line: e?.line, column: e?.column });
  }
};
